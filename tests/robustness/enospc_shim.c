/* A write failure to inject with LD_PRELOAD: write(), pwrite() and their 64-bit and vector
 * variants return -1 with errno = ENOSPC ("no space left on device") for files whose path
 * contains CAIRN_ENOSPC_MATCH, once CAIRN_ENOSPC_AFTER bytes (default 0) have been written to
 * such files (CAIRN_ENOSPC_ERRNO, a number, picks another errno: EDQUOT for a quota, EIO for a
 * failing device). Everything else passes through. It stands in for a full disk in the robustness
 * tests: mounting a small tmpfs needs privileges a CI container may not have.
 *
 * HDF5 (sec2 driver) and the output layer call these through the dynamic linker, so the
 * interposition reaches them. */
#define _GNU_SOURCE
#include <dlfcn.h>
#include <errno.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/types.h>
#include <sys/uio.h>
#include <unistd.h>

static long long written = 0;

/* True when this write to fd must fail. */
static int must_fail(int fd, size_t count) {
  const char* match = getenv("CAIRN_ENOSPC_MATCH");
  if (!match || !*match || count == 0) return 0;
  char link[64], path[PATH_MAX];
  snprintf(link, sizeof link, "/proc/self/fd/%d", fd);
  const ssize_t n = readlink(link, path, sizeof path - 1);
  if (n <= 0) return 0;
  path[n] = '\0';
  if (!strstr(path, match)) return 0;
  const char* after = getenv("CAIRN_ENOSPC_AFTER");
  const long long limit = after ? atoll(after) : 0;
  if (written + (long long)count <= limit) {
    written += (long long)count;
    return 0;
  }
  const char* code = getenv("CAIRN_ENOSPC_ERRNO");
  errno = code ? atoi(code) : ENOSPC;
  return 1;
}


static ssize_t real_write(int fd, const void* buf, size_t count) {
  static ssize_t (*real)(int, const void*, size_t) = NULL;
  if (!real) real = (ssize_t(*)(int, const void*, size_t))dlsym(RTLD_NEXT, "write");
  return real(fd, buf, count);
}

ssize_t write(int fd, const void* buf, size_t count) {
  if (must_fail(fd, count)) return -1;
  return real_write(fd, buf, count);
}

ssize_t pwrite(int fd, const void* buf, size_t count, off_t offset) {
  static ssize_t (*real)(int, const void*, size_t, off_t) = NULL;
  if (!real) real = (ssize_t(*)(int, const void*, size_t, off_t))dlsym(RTLD_NEXT, "pwrite");
  if (must_fail(fd, count)) return -1;
  return real(fd, buf, count, offset);
}

ssize_t pwrite64(int fd, const void* buf, size_t count, off_t offset) {
  static ssize_t (*real)(int, const void*, size_t, off_t) = NULL;
  if (!real) real = (ssize_t(*)(int, const void*, size_t, off_t))dlsym(RTLD_NEXT, "pwrite64");
  if (must_fail(fd, count)) return -1;
  return real(fd, buf, count, offset);
}

ssize_t writev(int fd, const struct iovec* iov, int n) {
  static ssize_t (*real)(int, const struct iovec*, int) = NULL;
  if (!real) real = (ssize_t(*)(int, const struct iovec*, int))dlsym(RTLD_NEXT, "writev");
  size_t count = 0;
  for (int i = 0; i < n; ++i) count += iov[i].iov_len;
  if (must_fail(fd, count)) return -1;
  return real(fd, iov, n);
}
