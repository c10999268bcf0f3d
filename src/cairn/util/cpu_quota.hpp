// The CPU time a process may use, from its control groups: a container started with
// `docker run --cpus=2` or a Kubernetes CPU limit sees every processor of the host, but the
// kernel lets it run only quota / period processors' worth of time. OpenMP's default team is one
// thread per processor seen, so on a 64-core host with a 2-CPU limit a run would spread 64
// threads over 2 CPUs' worth of time slices, and each barrier would wait for threads throttled
// until the next period (docs/performance.md, "Threads on a shared machine").
#pragma once

#include <filesystem>
#include <optional>

namespace cairn {

/// Processors' worth of CPU time the control groups of the calling process allow (cgroup v2
/// `cpu.max`, or v1 `cpu.cfs_quota_us` / `cpu.cfs_period_us`), the smallest limit over its
/// group and every group above it; nullopt when none is limited or nothing can be read.
/// `proc_cgroup` is /proc/self/cgroup and `cgroup_root` the mount root of the hierarchies
/// (the arguments are for tests).
std::optional<double> cgroup_cpu_limit(const std::filesystem::path& proc_cgroup = "/proc/self/cgroup",
                                       const std::filesystem::path& cgroup_root = "/sys/fs/cgroup");

/// The thread count that a limit of `cpus` processors allows: cpus rounded up (a team that
/// gets 1.5 processors' worth of time still runs faster than one thread; the adaptive thread
/// count falls back to one thread where it does not), at least 1.
int threads_for_cpu_limit(double cpus);

}  // namespace cairn
