#!/bin/sh
# Runs one of the node checks (validate.mjs, render.mjs) of this folder; skips (exit 77) when its npm packages
# are not installed (scripts/test.sh installs them: npm ci in tests/gltf).
set -eu
here=$(dirname "$0")
if [ ! -d "$here/node_modules/gltf-validator" ] || [ ! -d "$here/node_modules/three" ] ||
   [ ! -d "$here/node_modules/playwright-core" ]; then
  echo "skipped: npm packages missing in $here (run scripts/test.sh, or npm ci there)"
  exit 77
fi
exec node "$@"
