// The CPU limit of the process's control groups (util/cpu_quota.hpp), read from made-up
// /proc/self/cgroup files and cgroup trees of both versions.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "cairn/util/cpu_quota.hpp"
#include "../support/fresh_dir.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

void write(const fs::path& file, const std::string& text) {
  fs::create_directories(file.parent_path());
  std::ofstream(file) << text;
}

class CpuQuota : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = test::fresh_dir("cpu_quota");
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  fs::path proc() const { return dir_ / "proc_self_cgroup"; }
  fs::path root() const { return dir_ / "sys_fs_cgroup"; }
  fs::path dir_;
};

TEST_F(CpuQuota, UnifiedHierarchyTakesTheSmallestLimitOfTheGroupAndItsParents) {
  write(proc(), "0::/machine/box\n");
  write(root() / "cgroup.controllers", "cpu memory\n");
  write(root() / "machine/box/cpu.max", "150000 100000\n");
  write(root() / "machine/cpu.max", "max 100000\n");
  auto limit = cgroup_cpu_limit(proc(), root());
  ASSERT_TRUE(limit.has_value());
  EXPECT_DOUBLE_EQ(*limit, 1.5);
  write(root() / "machine/cpu.max", "100000 100000\n");  // the parent allows less
  limit = cgroup_cpu_limit(proc(), root());
  ASSERT_TRUE(limit.has_value());
  EXPECT_DOUBLE_EQ(*limit, 1.0);
}

TEST_F(CpuQuota, NoLimitAnywhereIsNone) {
  write(proc(), "0::/user.slice\n");
  write(root() / "cgroup.controllers", "cpu\n");
  write(root() / "user.slice/cpu.max", "max 100000\n");
  EXPECT_FALSE(cgroup_cpu_limit(proc(), root()).has_value());
  // A namespaced container sees its own group as "/" at the root of the mount.
  write(proc(), "0::/\n");
  EXPECT_FALSE(cgroup_cpu_limit(proc(), root()).has_value());
  write(root() / "cpu.max", "200000 100000\n");
  const auto limit = cgroup_cpu_limit(proc(), root());
  ASSERT_TRUE(limit.has_value());
  EXPECT_DOUBLE_EQ(*limit, 2.0);
}

TEST_F(CpuQuota, VersionOneCpuControllerUnderEitherMountName) {
  write(proc(), "12:memory:/docker/abc\n4:cpu,cpuacct:/docker/abc\n1:name=systemd:/docker/abc\n");
  write(root() / "cpu,cpuacct/docker/abc/cpu.cfs_quota_us", "300000\n");
  write(root() / "cpu,cpuacct/docker/abc/cpu.cfs_period_us", "100000\n");
  auto limit = cgroup_cpu_limit(proc(), root());
  ASSERT_TRUE(limit.has_value());
  EXPECT_DOUBLE_EQ(*limit, 3.0);
  // -1: no quota.
  write(root() / "cpu,cpuacct/docker/abc/cpu.cfs_quota_us", "-1\n");
  EXPECT_FALSE(cgroup_cpu_limit(proc(), root()).has_value());
  // Without a cgroup namespace the path names the host's group, but the container's own group
  // is mounted at the root: the walk up to the mount finds it there.
  fs::remove_all(root());
  write(proc(), "3:cpu:/docker/abc\n");
  write(root() / "cpu/cpu.cfs_quota_us", "50000\n");
  write(root() / "cpu/cpu.cfs_period_us", "100000\n");
  limit = cgroup_cpu_limit(proc(), root());
  ASSERT_TRUE(limit.has_value());
  EXPECT_DOUBLE_EQ(*limit, 0.5);
}

TEST_F(CpuQuota, UnreadableOrMalformedFilesAreNoLimit) {
  EXPECT_FALSE(cgroup_cpu_limit(proc(), root()).has_value());  // no /proc file
  write(proc(), "garbage\n0::/a\n");
  write(root() / "cgroup.controllers", "cpu\n");
  write(root() / "a/cpu.max", "lots 100000\n");
  EXPECT_FALSE(cgroup_cpu_limit(proc(), root()).has_value());
  write(root() / "a/cpu.max", "100000 0\n");
  EXPECT_FALSE(cgroup_cpu_limit(proc(), root()).has_value());
}

TEST(CpuQuotaThreads, RoundsUpAndKeepsOneThread) {
  EXPECT_EQ(threads_for_cpu_limit(0.2), 1);
  EXPECT_EQ(threads_for_cpu_limit(1.0), 1);
  EXPECT_EQ(threads_for_cpu_limit(1.5), 2);
  EXPECT_EQ(threads_for_cpu_limit(2.0), 2);
  EXPECT_EQ(threads_for_cpu_limit(63.2), 64);
}

}  // namespace
}  // namespace cairn
