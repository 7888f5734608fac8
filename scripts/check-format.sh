#!/bin/sh
# Checks that every tracked C and C++ source (.c .cc .cpp .h .hpp) follows .clang-format, with
# `clang-format --dry-run --Werror`; third-party and generated code (third_party/, external/, *_autogen/) is left
# out. Prints the files that differ and exits 1 when any does, 0 when all conform, 2 when clang-format is missing.
#
#   scripts/check-format.sh          check (the ctest `format_check` runs this)
#   scripts/check-format.sh --fix    reformat the same files in place (clang-format -i)
#
# CLANG_FORMAT names another binary (default: clang-format, Debian's clang-format 14).
set -eu

root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"
clang_format=${CLANG_FORMAT:-clang-format}
fix=0
case "${1:-}" in
  --fix) fix=1 ;;
  "") ;;
  *) echo "usage: scripts/check-format.sh [--fix]" >&2; exit 2 ;;
esac
if ! command -v "$clang_format" >/dev/null 2>&1; then
  echo "check-format: '$clang_format' not found (Debian: apt-get install clang-format)" >&2
  exit 2
fi

# the tracked sources (every source under the tree when this is not a git checkout)
list_sources() {
  if git rev-parse --is-inside-work-tree >/dev/null 2>&1; then
    git ls-files -- '*.c' '*.cc' '*.cpp' '*.h' '*.hpp'
  else
    find . -path ./build -prune -o -type f \( -name '*.c' -o -name '*.cc' -o -name '*.cpp' -o -name '*.h' -o -name '*.hpp' \) -print |
      sed 's|^\./||'
  fi | grep -v -E '(^|/)(third_party|external|build[^/]*)/|_autogen/'
}

total=0
differ=0
for f in $(list_sources); do
  total=$((total + 1))
  if [ "$fix" -eq 1 ]; then
    "$clang_format" -i --style=file "$f"
  elif ! "$clang_format" --dry-run --Werror --style=file "$f" >/dev/null 2>&1; then
    echo "$f"
    differ=$((differ + 1))
  fi
done
if [ "$fix" -eq 1 ]; then
  echo "check-format: reformatted $total files"
  exit 0
fi
if [ "$differ" -gt 0 ]; then
  echo "check-format: $differ of $total files differ from .clang-format (scripts/check-format.sh --fix reformats them)" >&2
  exit 1
fi
echo "check-format: all $total files follow .clang-format"
