#include "cairn/util/child_process.hpp"

#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>
#include <stdexcept>

namespace cairn {

#if defined(__SANITIZE_ADDRESS__)
#define CAIRN_CHILD_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CAIRN_CHILD_ASAN 1
#endif
#endif

namespace {

#ifdef CAIRN_CHILD_ASAN
constexpr bool capture_errors = false;  // the sanitizer's reports go to the terminal
#else
constexpr bool capture_errors = true;
#endif

}  // namespace

bool child_errors_captured() { return capture_errors; }

ChildResult run_in_child(const std::function<int(std::string& out)>& work, int timeout_seconds) {
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error(std::string("cannot create a pipe: ") + std::strerror(errno));
  int err[2] = {-1, -1};
  if (capture_errors && ::pipe(err) != 0) {
    const int e = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::runtime_error(std::string("cannot create a pipe: ") + std::strerror(e));
  }
  auto close_all = [&] {
    for (int fd : {fds[0], fds[1], err[0], err[1]})
      if (fd >= 0) ::close(fd);
  };
  const pid_t child = ::fork();
  if (child < 0) {
    const int e = errno;
    close_all();
    throw std::runtime_error(std::string("cannot start a process: ") + std::strerror(e));
  }
  if (child == 0) {
    ::close(fds[0]);
    if (capture_errors) {
      ::close(err[0]);
      ::dup2(err[1], STDERR_FILENO);
      ::close(err[1]);
    }
    // A fault ends the child by its signal, whatever handler the parent installed.
    for (int sig : {SIGSEGV, SIGBUS, SIGFPE, SIGILL, SIGABRT}) ::signal(sig, SIG_DFL);
    std::string out;
    int code = 125;
    try {
      code = work(out);
    } catch (...) {
      code = 125;
    }
    for (std::size_t at = 0; at < out.size();) {
      const ssize_t n = ::write(fds[1], out.data() + at, out.size() - at);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) ::_exit(126);
      at += static_cast<std::size_t>(n);
    }
    ::_exit(code);
  }
  ::close(fds[1]);
  if (capture_errors) ::close(err[1]);
  ChildResult result;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_seconds);
  // Both pipes are read as the child writes (a child whose standard error fills its pipe would
  // otherwise wait for ever); the answer pipe closing means the child has finished, and what it
  // wrote to its standard error before is in that pipe by then.
  pollfd p[2] = {{fds[0], POLLIN, 0}, {capture_errors ? err[0] : -1, POLLIN, 0}};
  for (char buffer[65536]; p[0].fd >= 0;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      result.timed_out = true;
      break;
    }
    const int ready = ::poll(p, 2, static_cast<int>(std::min<long long>(left, 1000)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    for (int k = 0; k < 2; ++k) {
      if (p[k].fd < 0 || p[k].revents == 0) continue;
      const ssize_t n = ::read(p[k].fd, buffer, sizeof buffer);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {  // the child closed its end
        ::close(p[k].fd);
        p[k].fd = -1;
        continue;
      }
      std::string& into = k == 0 ? result.output : result.errors;
      into.append(buffer, static_cast<std::size_t>(n));
      if (k == 1 && into.size() > 2 * child_errors_kept) into.erase(0, into.size() - child_errors_kept);
    }
  }
  if (p[0].fd >= 0) ::close(p[0].fd);
  if (result.timed_out) ::kill(child, SIGKILL);
  // What is left of its standard error: the child has ended (or been killed), so the pipe ends,
  // unless a process the child started holds it: then no more than a second's wait.
  for (char buffer[65536]; p[1].fd >= 0;) {
    const int ready = ::poll(&p[1], 1, 1000);
    if (ready < 0 && errno == EINTR) continue;
    if (ready <= 0) {
      ::close(p[1].fd);
      p[1].fd = -1;
      break;
    }
    const ssize_t n = ::read(p[1].fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      ::close(p[1].fd);
      p[1].fd = -1;
      break;
    }
    result.errors.append(buffer, static_cast<std::size_t>(n));
  }
  if (result.errors.size() > child_errors_kept) result.errors.erase(0, result.errors.size() - child_errors_kept);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status) && !result.timed_out) result.signal = WTERMSIG(status);
  if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  return result;
}

void limit_address_space(double bytes) {
#ifdef CAIRN_CHILD_ASAN
  (void)bytes;
#else
  std::ifstream statm("/proc/self/statm");
  double pages = 0.0;
  statm >> pages;
  const double limit = pages * static_cast<double>(::sysconf(_SC_PAGESIZE)) + bytes;
  const rlimit r{static_cast<rlim_t>(limit), static_cast<rlim_t>(limit)};
  ::setrlimit(RLIMIT_AS, &r);
#endif
}

std::string child_ending(const ChildResult& result, int timeout_seconds) {
  if (result.timed_out) return "it did not finish in " + std::to_string(timeout_seconds) + " s" + child_said(result);
  if (result.signal != 0) return "signal " + std::to_string(result.signal) + child_said(result);
  return "exit code " + std::to_string(result.exit_code) + child_said(result);
}

std::string child_said(const ChildResult& result) {
  const std::string& e = result.errors;
  std::size_t end = e.find_last_not_of(" \t\r\n");
  if (end == std::string::npos) return "";
  const std::size_t newline = e.find_last_of("\r\n", end);
  const std::size_t begin = newline == std::string::npos ? 0 : newline + 1;
  std::string line = e.substr(begin, std::min<std::size_t>(end + 1 - begin, 200));
  for (char& c : line)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) c = '?';  // no control characters in a message
  return "; it printed \"" + line + "\"";
}

bool AnswerReader::take(void* p, std::size_t n) {
  if (n > answer_.size() || at_ > answer_.size() - n) return false;
  if (n > 0) std::memcpy(p, answer_.data() + at_, n);  // (an empty string's data() is never read)
  at_ += n;
  return true;
}

}  // namespace cairn
