// The compiled part of the Python module `cairn` (docs/python.md): `_cairn`, wrapped by the
// pure-Python package python/cairn/. Version, build options and the OpenMP thread count the
// `cairn` command would use.
#include <omp.h>

#include <cstdlib>

#include "bindings.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/util/cpu_quota.hpp"

namespace cairn::python {
namespace {

/// As `cairn run` without -t and without OMP_NUM_THREADS (app/main.cpp): no more threads than
/// the CPU time the control groups allow (a container's CPU limit). Returns the thread count.
int limit_threads_to_cpu_quota() {
  if (std::getenv("OMP_NUM_THREADS") == nullptr)
    if (const auto cpus = cgroup_cpu_limit()) {
      const int allowed = threads_for_cpu_limit(*cpus);
      if (allowed < omp_get_max_threads()) omp_set_num_threads(allowed);
    }
  return omp_get_max_threads();
}

}  // namespace
}  // namespace cairn::python

PYBIND11_MODULE(_cairn, m) {
  namespace py = pybind11;
  using namespace cairn::python;
  m.doc() = "Cairn's engine, compiled (use the package `cairn`, docs/python.md)";
  m.attr("__version__") = CAIRN_VERSION;
  py::dict build;
  build["mpi"] = cairn::built_with_mpi();
  build["openmp"] = true;
  build["openmp_max_threads"] = omp_get_num_procs();
  m.attr("build") = build;
  limit_threads_to_cpu_quota();
  m.def("threads", [] { return omp_get_max_threads(); }, "OpenMP threads a run uses (as `cairn run` would).");
  m.def(
      "set_threads", [](int n) { omp_set_num_threads(n); }, py::arg("n"),
      "Use n OpenMP threads from now on (as `cairn run -t n`; simulation.threads still wins).");
  bind_input(m);
  bind_engine(m);
}
