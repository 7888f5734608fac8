/* A disk that fills up, for the tests: preloaded into pneuma-cli (LD_PRELOAD), it lets write() and writev()
 * to files under $PNEUMA_FULLDISK_DIR (an absolute, canonical path) store $PNEUMA_FULLDISK_BYTES bytes in
 * all; after that they fail with ENOSPC, the first one short, as on a real full disk. Other files are
 * untouched. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

static const char* g_dir = NULL;
static size_t g_dirLength = 0;
static long long g_budget = -1; /* bytes still free; -1 until read from the environment */

static void setUp(void) {
  if (g_budget >= 0 || g_dir != NULL) return;
  g_dir = getenv("PNEUMA_FULLDISK_DIR");
  const char* bytes = getenv("PNEUMA_FULLDISK_BYTES");
  g_budget = bytes != NULL ? atoll(bytes) : 0;
  g_dirLength = g_dir != NULL ? strlen(g_dir) : 0;
}

/* whether fd is a file under the full directory */
static int isOnFullDisk(int fd) {
  setUp();
  if (g_dir == NULL || g_dirLength == 0) return 0;
  char link[64], target[4096];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t n = readlink(link, target, sizeof target - 1);
  if (n <= 0) return 0;
  target[n] = '\0';
  return strncmp(target, g_dir, g_dirLength) == 0 &&
         (target[g_dirLength] == '/' || target[g_dirLength] == '\0');
}

/* how many of `count` bytes fit; -1 with errno ENOSPC when none does */
static ssize_t allowance(int fd, size_t count) {
  if (!isOnFullDisk(fd)) return (ssize_t)count;
  if (g_budget <= 0) {
    errno = ENOSPC;
    return -1;
  }
  const size_t n = (long long)count < g_budget ? count : (size_t)g_budget;
  g_budget -= (long long)n;
  return (ssize_t)n;
}

ssize_t write(int fd, const void* buf, size_t count) {
  static ssize_t (*real)(int, const void*, size_t) = NULL;
  if (real == NULL) real = (ssize_t(*)(int, const void*, size_t))dlsym(RTLD_NEXT, "write");
  const ssize_t n = allowance(fd, count);
  if (n < 0) return -1;
  return real(fd, buf, (size_t)n);
}

ssize_t writev(int fd, const struct iovec* iov, int iovcnt) {
  static ssize_t (*real)(int, const struct iovec*, int) = NULL;
  if (real == NULL) real = (ssize_t(*)(int, const struct iovec*, int))dlsym(RTLD_NEXT, "writev");
  size_t total = 0;
  for (int i = 0; i < iovcnt; ++i) total += iov[i].iov_len;
  const ssize_t n = allowance(fd, total);
  if (n < 0) return -1;
  if ((size_t)n == total) return real(fd, iov, iovcnt);
  /* short: write the first n bytes only */
  ssize_t done = 0;
  for (int i = 0; i < iovcnt && done < n; ++i) {
    const size_t part = iov[i].iov_len < (size_t)(n - done) ? iov[i].iov_len : (size_t)(n - done);
    static ssize_t (*realWrite)(int, const void*, size_t) = NULL;
    if (realWrite == NULL) realWrite = (ssize_t(*)(int, const void*, size_t))dlsym(RTLD_NEXT, "write");
    const ssize_t w = realWrite(fd, iov[i].iov_base, part);
    if (w < 0) return done > 0 ? done : -1;
    done += w;
  }
  return done;
}
