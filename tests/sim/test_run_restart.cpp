// The run loop: a run restarted from a mid-way checkpoint ends bit-identical to one that never
// stopped; a failing run stops with a diagnosis and keeps its last good output; the CLI exit
// codes (2 bad input, 3 failed run).
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "../support/fresh_dir.hpp"
#include "cairn/io/checkpoint.hpp"
#include "cairn/input/input.hpp"
#include "cairn/run/engine.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;

const char* block_input = R"toml(
[simulation]
dimension = 2
end_time = 2.0e-4
cfl = 0.3
[grid]
origin = [0.0, 0.0]
extent = [0.02, 0.01]
cell_size = 1.0e-3
[method]
shape = "bspline2"
[[material]]
name = "rubber"
model = "neo_hookean"
density = 1000.0
youngs_modulus = 1.0e7
poissons_ratio = 0.3
[[body]]
material = "rubber"
shape = { box = { min = [0.004, 0.002], max = [0.012, 0.008] } }
velocity = ["20*(Y-0.005)", "-10*(X-0.008)"]
[boundary]
y_min = "fixed"
[output]
every = 5.0e-5
checkpoint_every = 1.0e-4
)toml";

using test::fresh_dir;

TEST(RunLoop, TimeStepNoteForFmpmAboveItsCriticalCfl) {
  // FMPM(k) lowers the critical time step by up to sqrt(k) (docs/update-schemes.md): a note when
  // cfl * sqrt(k) > 0.6 under the CFL rule, nothing otherwise.
  auto note = [](const std::vector<std::string>& sets) {
    return time_step_note(load_config_string(block_input, "block.toml", sets));
  };
  EXPECT_NE(note({"method.update=\"fmpm\"", "method.order=4", "simulation.cfl=0.5"}).find("FMPM(4)"),
            std::string::npos);
  EXPECT_NE(note({"method.update=\"fmpm\"", "method.order=2", "simulation.cfl=0.5"}), "");
  EXPECT_EQ(note({"method.update=\"fmpm\"", "method.order=4", "simulation.cfl=0.2"}), "");
  EXPECT_EQ(note({"method.update=\"fmpm\"", "method.order=8", "simulation.cfl=0.2"}), "");
  EXPECT_EQ(note({"method.update=\"xpic\"", "method.order=8", "simulation.cfl=0.5"}), "");
  EXPECT_EQ(note({"method.update=\"fmpm\"", "method.order=8", "simulation.dt=1e-7"}), "");
  EXPECT_EQ(note({}), "");
}

/// Runs block_input (with `sets`) to the end, restarts it from its mid-way checkpoint and checks
/// that both end bit-identical: particle state, history rows and history text.
void expect_bit_identical_restart(const std::string& name, std::vector<std::string> sets,
                                  const char* input = block_input) {
  const fs::path a = fresh_dir(name + "_full"), b = fresh_dir(name + "_restarted");
  RunOptions quiet{true};
  sets.push_back("output.directory=\"" + a.string() + "\"");
  const Config ca = load_config_string(input, "input.toml", sets);
  const RunSummary full = run(ca, quiet);
  ASSERT_TRUE(fs::exists(a / "checkpoint-0000.h5"));  // mid-way, t = 1e-4
  const RunSummary rest = restart(a / "checkpoint-0000.h5", {"output.directory=\"" + b.string() + "\""}, quiet);
  EXPECT_GT(rest.steps, 0);
  EXPECT_LT(rest.steps, full.steps);
  const auto end_a = read_checkpoint<2>(full.last_checkpoint);
  const auto end_b = read_checkpoint<2>(rest.last_checkpoint);
  EXPECT_EQ(end_a.time, end_b.time);
  EXPECT_EQ(end_a.step, end_b.step);
  ASSERT_EQ(end_a.particles.n(), end_b.particles.n());
  for (std::size_t p = 0; p < end_a.particles.n(); ++p) {
    ASSERT_EQ(end_a.particles.position[p], end_b.particles.position[p]) << p;
    ASSERT_EQ(end_a.particles.velocity[p], end_b.particles.velocity[p]) << p;
    ASSERT_EQ(end_a.particles.deformation_gradient[p], end_b.particles.deformation_gradient[p]) << p;
    ASSERT_EQ(end_a.particles.kirchhoff_stress[p], end_b.particles.kirchhoff_stress[p]) << p;
  }
  EXPECT_EQ(end_a.history_rows, end_b.history_rows);
  std::ifstream ha(a / "history.csv"), hb(b / "history.csv");
  std::stringstream sa, sb;
  sa << ha.rdbuf();
  sb << hb.rdbuf();
  EXPECT_EQ(sa.str(), sb.str());
  fs::remove_all(a);
  fs::remove_all(b);
}

TEST(RunLoop, RestartFromMidwayCheckpointIsBitIdentical) { expect_bit_identical_restart("mpm", {}); }

TEST(RunLoop, WlsRestartFromMidwayCheckpointIsBitIdentical) {
  // The WLS method of seed 001 (docs/wls.md): its centred-difference step takes a half first step
  // (Eq. 25-30), which a restart must not take again.
  expect_bit_identical_restart("wls", {"method.integration=\"wls\""});
}

TEST(RunLoop, WlsEnergyBudgetRestartsBitIdentical) {
  // method.energy_budget (docs/wls.md, "Energy budget"): the checkpoint keeps both sums, so the
  // history's wls_grid_work and wls_transfer_energy continue where they were.
  expect_bit_identical_restart("wls_budget", {"method.integration=\"wls\"", "method.energy_budget=true"});
}

/// Two disks meeting at +-30 m/s under Coulomb friction (body mode), checkpoints mid-impact.
const char* const contact_disks = R"toml(
[simulation]
dimension = 2
end_time = 3.0e-4
cfl = 0.25
[grid]
origin = [0.0, 0.0]
extent = [0.056, 0.032]
cell_size = 2.0e-3
[method]
shape = "bspline2"
update = "xpic"
order = 3
[contact]
mode = "body"
normal = "lr"
detection = "lr"
law = "coulomb"
friction = 0.3
release = "separation"
[[material]]
name = "soft"
model = "neo_hookean"
density = 1000.0
lambda = 2.0e6
shear_modulus = 1.0e6
[[body]]
name = "a"
material = "soft"
shape = { circle = { center = [0.017, 0.015], radius = 0.009 } }
velocity = [30.0, 3.0]
[[body]]
name = "b"
material = "soft"
shape = { circle = { center = [0.037, 0.017], radius = 0.009 } }
velocity = [-30.0, 0.0]
[output]
every = 1.5e-4
history_every = 3.0e-5
checkpoint_every = 1.5e-4
)toml";

TEST(RunLoop, ContactReleasedBySeparationRestartsBitIdentical) {
  // [contact] release = "separation" keeps a pair in contact by the last step's record: the
  // checkpoint stores the record (/contact/in_contact). Without it this restart, from the middle
  // of the impact, differs from the uninterrupted run in the history's next rows.
  expect_bit_identical_restart("contact_release", {}, contact_disks);
}

TEST(RunLoop, WlsContactRestartsBitIdentical) {
  // WLS bodies in contact (docs/wls.md, "Contact"): each field's integrator rebuilds everything
  // from the particles every step, so the particles, the contact record and the energy budget's
  // totals are all a restart from the middle of the impact needs.
  expect_bit_identical_restart("wls_contact",
                               {"method.integration=\"wls\"", "method.time_integration=\"central_difference\"",
                                "method.energy_budget=true"},
                               contact_disks);
}

int run_cli(const std::string& args, const fs::path& log) {
  const std::string cmd = std::string(CAIRN_BINARY) + " " + args + " > " + log.string() + " 2>&1";
  const int status = std::system(cmd.c_str());
  return WEXITSTATUS(status);
}

std::string read(const fs::path& p) {
  std::ifstream f(p);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

TEST(RunLoop, UnstableRunStopsWithDiagnosisAndKeepsLastGoodOutput) {
  const fs::path d = fresh_dir("unstable");
  fs::create_directories(d);
  std::ofstream(d / "case.toml") << block_input;
  // A time step four times the stable one (~7.6e-6 here) inverts particles within a few steps.
  const int code = run_cli("run " + (d / "case.toml").string() + " -q --set simulation.dt=3e-5" +
                               " --set output.directory=\"" + (d / "out").string() + "\"",
                           d / "log.txt");
  const std::string log = read(d / "log.txt");
  EXPECT_EQ(code, 3) << log;
  EXPECT_NE(log.find("particle "), std::string::npos) << log;
  EXPECT_NE(log.find("at step "), std::string::npos) << log;
  EXPECT_TRUE(fs::exists(d / "out" / "history.csv"));
  EXPECT_TRUE(fs::exists(d / "out" / "failure.xdmf")) << log;
  EXPECT_TRUE(fs::exists(d / "out" / "snapshots" / "particles-000000.h5"));
  fs::remove_all(d);
}

TEST(RunLoop, ParticleLeavingTheGridIsNamed) {
  const fs::path d = fresh_dir("escape");
  fs::create_directories(d);
  std::ofstream(d / "case.toml") << block_input;
  const int code = run_cli("run " + (d / "case.toml").string() + " -q --set 'body.0.velocity=[400.0, 0.0]'" +
                               " --set output.directory=\"" + (d / "out").string() + "\"",
                           d / "log.txt");
  const std::string log = read(d / "log.txt");
  EXPECT_EQ(code, 3) << log;
  EXPECT_NE(log.find("left the grid"), std::string::npos) << log;
  fs::remove_all(d);
}

TEST(RunLoop, BadInputExitsWithCode2AndNamesTheKey) {
  const fs::path d = fresh_dir("badinput");
  fs::create_directories(d);
  std::ofstream(d / "case.toml") << block_input;
  const int code = run_cli("run " + (d / "case.toml").string() + " -q --set method.shape=cpdii", d / "log.txt");
  const std::string log = read(d / "log.txt");
  EXPECT_EQ(code, 2) << log;
  EXPECT_NE(log.find("method.shape"), std::string::npos) << log;
  EXPECT_NE(log.find("cpdii"), std::string::npos) << log;
  const int missing = run_cli("run " + (d / "nope.toml").string(), d / "log2.txt");
  EXPECT_EQ(missing, 2) << read(d / "log2.txt");
  fs::remove_all(d);
}

}  // namespace
}  // namespace cairn
