// One outcome on every rank for a check the ranks make together (docs/parallel.md, "Errors"):
// each rank runs its part, and an error on any of them stops all of them with one message, so
// that no rank waits in a collective call for a rank that has already left.
#pragma once

#include <cstdint>
#include <new>
#include <stdexcept>
#include <string>

#include "cairn/config/errors.hpp"
#include "cairn/parallel/comm.hpp"

namespace cairn {

/// Run `fn` on every rank of `comm` (collective). If it throws on any rank, every rank throws the
/// error of the lowest rank that failed, with its text: an input error (InputError,
/// std::invalid_argument) as std::invalid_argument (exit 2), running out of memory as
/// std::bad_alloc, any other std::exception as std::runtime_error (exit 1). On one rank fn's own
/// exception passes through unchanged.
template <class Fn>
void agree_on_errors(const Comm& comm, Fn&& fn) {
  if (!comm.parallel()) {
    fn();
    return;
  }
  std::string problem;  // empty, or its kind ('2' input, 'm' memory, '1' other) and its text
  try {
    fn();
  } catch (const InputError& e) {
    problem = std::string("2") + e.what();
  } catch (const std::invalid_argument& e) {
    problem = std::string("2") + e.what();
  } catch (const std::bad_alloc&) {
    problem = "m";
  } catch (const std::exception& e) {
    problem = std::string("1") + e.what();
  }
  const std::int64_t first = comm.min(problem.empty() ? std::int64_t{comm.size()} : std::int64_t{comm.rank()});
  if (first == comm.size()) return;
  comm.broadcast(problem, static_cast<int>(first));
  if (problem[0] == '2') throw std::invalid_argument(problem.substr(1));
  if (problem[0] == 'm') throw std::bad_alloc();
  throw std::runtime_error(problem.substr(1));
}

}  // namespace cairn
