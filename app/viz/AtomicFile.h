#pragma once
/// @file AtomicFile.h
/// Writing output files so that an interrupted or failed run never leaves a half-written file that
/// looks complete: everything goes to "<path>.tmp-<pid>" first and is renamed into place at the end.

#include <string>

namespace pneuma::viz {

/// The temporary name used for `path` while it is being written ("<path>.tmp-<pid>").
std::string temporaryPathFor(const std::string& path);

/// Renames `temporaryPath` to `path` (atomic on POSIX within one file system).
/// @throws std::runtime_error naming both paths when the rename fails.
void commitTemporary(const std::string& temporaryPath, const std::string& path);

/// Writes `bytes` to `path` through temporaryPathFor(path) and a rename.
/// @throws std::runtime_error naming the path when it cannot be written.
void writeFileAtomically(const std::string& path, const std::string& bytes);

}  // namespace pneuma::viz
