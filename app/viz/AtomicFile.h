#pragma once
/// @file AtomicFile.h
/// Writing output files so that an interrupted or failed run never leaves a half-written file that
/// looks complete: everything goes to "<path>.tmp-<pid>" first and is renamed into place at the end.
/// Every write and the close are checked, so a full disk or a quota is an error naming the file and the
/// reason ("cannot write out/summary.json: No space left on device"), never a truncated file under its name.

#include <string>
#include <string_view>

namespace pneuma::viz {

/// The temporary name used for `path` while it is being written ("<path>.tmp-<pid>").
std::string temporaryPathFor(const std::string& path);

/// Renames `temporaryPath` to `path` (atomic on POSIX within one file system).
/// @throws std::runtime_error naming both paths when the rename fails.
void commitTemporary(const std::string& temporaryPath, const std::string& path);

/// Writes `bytes` to `path` through temporaryPathFor(path) and a rename.
/// @throws std::runtime_error "cannot write <path>: <reason>" when it cannot be written; the temporary
///         file is removed and `path` keeps what it held before.
void writeFileAtomically(const std::string& path, std::string_view bytes);

/// A file written piece by piece (a CSV that grows with the run) to temporaryPathFor(path), renamed into
/// place by commit(). Destroyed without commit(), it removes the temporary file.
class AtomicFileWriter {
 public:
  /// Creates the temporary file. @throws std::runtime_error "cannot write <path>: <reason>".
  explicit AtomicFileWriter(std::string path);
  ~AtomicFileWriter();
  AtomicFileWriter(const AtomicFileWriter&) = delete;
  AtomicFileWriter& operator=(const AtomicFileWriter&) = delete;

  /// Appends `bytes` (buffered). @throws std::runtime_error "cannot write <path>: <reason>".
  void write(std::string_view bytes);
  /// Flushes, closes and renames the file into place. @throws std::runtime_error as write().
  void commit();
  const std::string& path() const { return m_path; }

 private:
  void flush();
  [[noreturn]] void failWith(int error);
  std::string m_path;
  std::string m_temporary;
  std::string m_buffer;
  std::string m_error;  // the message of the failure that closed the file, repeated by later calls
  int m_fd = -1;
};

}  // namespace pneuma::viz
