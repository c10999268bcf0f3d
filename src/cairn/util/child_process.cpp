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

ChildResult run_in_child(const std::function<int(std::string& out)>& work, int timeout_seconds) {
  int fds[2];
  if (::pipe(fds) != 0) throw std::runtime_error(std::string("cannot create a pipe: ") + std::strerror(errno));
  const pid_t child = ::fork();
  if (child < 0) {
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::runtime_error(std::string("cannot start a process: ") + std::strerror(errno));
  }
  if (child == 0) {
    ::close(fds[0]);
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
  ChildResult result;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(timeout_seconds);
  for (char buffer[65536];;) {
    const auto left =
        std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now()).count();
    if (left <= 0) {
      result.timed_out = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, static_cast<int>(std::min<long long>(left, 1000)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // the child closed its end: it has finished
    result.output.append(buffer, static_cast<std::size_t>(n));
  }
  ::close(fds[0]);
  if (result.timed_out) ::kill(child, SIGKILL);
  int status = 0;
  while (::waitpid(child, &status, 0) < 0 && errno == EINTR) {
  }
  if (WIFSIGNALED(status) && !result.timed_out) result.signal = WTERMSIG(status);
  if (WIFEXITED(status)) result.exit_code = WEXITSTATUS(status);
  return result;
}

void limit_address_space(double bytes) {
#if defined(__SANITIZE_ADDRESS__)
#define CAIRN_CHILD_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define CAIRN_CHILD_ASAN 1
#endif
#endif
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
  if (result.timed_out) return "it did not finish in " + std::to_string(timeout_seconds) + " s";
  if (result.signal != 0) return "signal " + std::to_string(result.signal);
  return "exit code " + std::to_string(result.exit_code);
}

bool AnswerReader::take(void* p, std::size_t n) {
  if (n > answer_.size() || at_ > answer_.size() - n) return false;
  if (n > 0) std::memcpy(p, answer_.data() + at_, n);  // (an empty string's data() is never read)
  at_ += n;
  return true;
}

}  // namespace cairn
