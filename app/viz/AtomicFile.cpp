#include "viz/AtomicFile.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

namespace pneuma::viz {

namespace {

constexpr std::size_t kBufferBytes = 1 << 16;  // AtomicFileWriter's buffer

std::runtime_error writeError(const std::string& path, int error) {
  return std::runtime_error("cannot write " + path + ": " + std::strerror(error));
}

// writes all of `bytes` to `fd`; 0, or the errno of the failing write
int writeAll(int fd, std::string_view bytes) {
  while (!bytes.empty()) {
    const ssize_t n = ::write(fd, bytes.data(), bytes.size());
    if (n < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    if (n == 0) return ENOSPC;
    bytes.remove_prefix(static_cast<std::size_t>(n));
  }
  return 0;
}

int openTemporary(const std::string& tmp) {
  return ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
}

}  // namespace

std::string temporaryPathFor(const std::string& path) {
  return path + ".tmp-" + std::to_string(static_cast<long>(getpid()));
}

void commitTemporary(const std::string& temporaryPath, const std::string& path) {
  if (std::rename(temporaryPath.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    std::remove(temporaryPath.c_str());
    throw std::runtime_error("cannot rename " + temporaryPath + " to " + path + ": " + reason);
  }
}

void writeFileAtomically(const std::string& path, std::string_view bytes) {
  AtomicFileWriter file(path);
  file.write(bytes);
  file.commit();
}

AtomicFileWriter::AtomicFileWriter(std::string path)
    : m_path(std::move(path)), m_temporary(temporaryPathFor(m_path)) {
  m_fd = openTemporary(m_temporary);
  if (m_fd < 0) throw writeError(m_path, errno);
}

AtomicFileWriter::~AtomicFileWriter() {
  if (m_fd < 0) return;
  ::close(m_fd);
  std::remove(m_temporary.c_str());
}

void AtomicFileWriter::failWith(int error) {
  ::close(m_fd);
  m_fd = -1;
  std::remove(m_temporary.c_str());
  const std::runtime_error e = writeError(m_path, error);
  m_error = e.what();
  throw e;
}

void AtomicFileWriter::flush() {
  if (m_fd < 0)
    throw std::runtime_error(m_error.empty() ? "cannot write " + m_path + ": already closed" : m_error);
  if (const int error = writeAll(m_fd, m_buffer)) failWith(error);
  m_buffer.clear();
}

void AtomicFileWriter::write(std::string_view bytes) {
  if (m_buffer.size() + bytes.size() > kBufferBytes) {
    flush();
    if (bytes.size() > kBufferBytes) {
      if (const int error = writeAll(m_fd, bytes)) failWith(error);
      return;
    }
  }
  m_buffer.append(bytes);
}

void AtomicFileWriter::commit() {
  flush();
  const int fd = m_fd;
  m_fd = -1;
  if (::close(fd) != 0) {
    const int error = errno;
    std::remove(m_temporary.c_str());
    throw writeError(m_path, error);
  }
  commitTemporary(m_temporary, m_path);
}

}  // namespace pneuma::viz
