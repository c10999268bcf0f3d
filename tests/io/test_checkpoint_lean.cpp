// Checkpoints of lean particle storage: written from the simulation's own arrays (no copy of the
// particles), without the arrays a run does not store (APIC's C_p, temperatures), and read back
// bit for bit.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstring>
#include <filesystem>
#include <string>

#include "cairn/io/checkpoint.hpp"

namespace fs = std::filesystem;
using namespace cairn;

namespace {

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof a) == 0; }

Particles<2> lean_particles(std::size_t n) {
  Particles<2> ps;
  ps.has_affine = false;
  ps.has_temperature = false;
  for (std::size_t p = 0; p < n; ++p) {
    const double s = static_cast<double>(p);
    ps.add(Vec<2>(0.1 * s, -0.3 * s), Vec<2>(1.0 / (s + 3.0), s), 2.0 + s, 0.5, Vec<2>(0.1, 0.2), 0, 1);
    Mat3 F = Mat3::Identity();
    F(0, 1) = 0.01 * s;
    F(1, 0) = -1.0 / (7.0 + s);
    ps.deformation_gradient.back() = F;
    Mat3 tau = Mat3::Zero();
    tau(0, 0) = 1e9 / (s + 1.0);
    tau(0, 1) = tau(1, 0) = -3.0 * s;
    tau(2, 2) = 0.1;
    ps.kirchhoff_stress.back() = tau;
  }
  return ps;
}

}  // namespace

TEST(CheckpointLean, ParticlesWithoutAffineOrTemperatureRoundTripFromTheLiveArrays) {
  const fs::path dir = fs::temp_directory_path() / ("cairn_lean_" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const Particles<2> live = lean_particles(300000);  // more than one write block of the matrices
  ASSERT_TRUE(live.affine_velocity.empty());
  ASSERT_TRUE(live.temperature.empty());
  CheckpointData<2> data;  // data.particles stays empty: the particles come from `live`
  data.config_toml = "x = 1";
  data.history_columns = {"time"};
  write_checkpoint<2>(dir / "c.h5", data, live);
  const CheckpointData<2> back = read_checkpoint<2>(dir / "c.h5");
  const Particles<2>& b = back.particles;
  ASSERT_EQ(b.n(), live.n());
  EXPECT_FALSE(b.has_affine);
  EXPECT_FALSE(b.has_temperature);
  EXPECT_TRUE(b.affine_velocity.empty());
  EXPECT_TRUE(b.temperature.empty());
  for (std::size_t p = 0; p < live.n(); ++p) {
    for (int a = 0; a < 2; ++a) {
      ASSERT_TRUE(same_bits(b.position[p][a], live.position[p][a])) << p;
      ASSERT_TRUE(same_bits(b.velocity[p][a], live.velocity[p][a])) << p;
    }
    for (int i = 0; i < 9; ++i)
      ASSERT_TRUE(same_bits(b.deformation_gradient[p].data()[i], live.deformation_gradient[p].data()[i])) << p;
    for (int k = 0; k < 6; ++k)
      ASSERT_TRUE(same_bits(b.kirchhoff_stress[p].voigt()[k], live.kirchhoff_stress[p].voigt()[k])) << p;
    ASSERT_EQ(b.body[p], 1);
  }
  fs::remove_all(dir);
}
