// Engines (run/engine.hpp): the registry picks the engine an input asks for, a checkpoint names
// the engine that wrote it and restarts with it, and an engine stepped one call at a time (as the
// Python module drives it) writes what `cairn run` writes, to the bit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "../support/fresh_dir.hpp"
#include "cairn/input/input.hpp"
#include "cairn/io/checkpoint.hpp"
#include "cairn/run/engine.hpp"
#include "cairn/sim/simulation.hpp"

namespace cairn {
namespace {

namespace fs = std::filesystem;
using test::fresh_dir;

const char* block_input = R"toml(
[simulation]
dimension = 2
end_time = 1.0e-4
cfl = 0.3
[grid]
origin = [0.0, 0.0]
extent = [0.02, 0.01]
cell_size = 1.0e-3
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
[output]
every = 5.0e-5
)toml";

Config block(const fs::path& out, std::vector<std::string> sets = {}) {
  sets.push_back("output.directory=\"" + out.string() + "\"");
  return load_config_string(block_input, "block.toml", sets);
}

std::string text_of(const fs::path& file) {
  std::ifstream in(file);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(Engines, TheRegistryPicksTheEngineAnInputAsksFor) {
  const auto& registry = EngineRegistry::instance();
  EXPECT_EQ(registry.names(), (std::vector<std::string>{"fem", "mpm", "wls"}));
  const fs::path out = fresh_dir("engine_pick");
  EXPECT_EQ(registry.name_for(block(out)), "mpm");
  EXPECT_EQ(registry.name_for(block(out, {"method.integration=\"wls\""})), "wls");
  const auto engine = make_engine(block(out), RunOptions{true});
  EXPECT_EQ(engine->name(), "mpm");
  EXPECT_TRUE(std::holds_alternative<Simulation<2>*>(engine->state()));
  EXPECT_GT(engine->items(), 0);
  EXPECT_THROW((void)registry.at("sph"), std::invalid_argument);
}

TEST(Engines, SteppedOneCallAtATimeWritesWhatRunWrites) {
  const fs::path a = fresh_dir("engine_run"), b = fresh_dir("engine_stepped");
  const RunSummary full = run(block(a), RunOptions{true});
  auto engine = make_engine(block(b), RunOptions{true});
  long long steps = 0;
  while (!engine->finished()) {
    engine->step();  // (start() is called by the first step)
    ++steps;
  }
  const RunSummary stepped = engine->finish();
  EXPECT_EQ(steps, full.steps);
  EXPECT_EQ(stepped.steps, full.steps);
  EXPECT_EQ(stepped.end_time, full.end_time);
  EXPECT_EQ(text_of(a / "history.csv"), text_of(b / "history.csv"));
  const auto ca = read_checkpoint<2>(a / "checkpoint-0000.h5"), cb = read_checkpoint<2>(b / "checkpoint-0000.h5");
  EXPECT_EQ(ca.particles.position, cb.particles.position);
  EXPECT_EQ(ca.particles.kirchhoff_stress, cb.particles.kirchhoff_stress);
}

TEST(Engines, ACheckpointNamesItsEngineAndRestartsWithIt) {
  const fs::path mpm = fresh_dir("engine_mpm"), wls = fresh_dir("engine_wls");
  run(block(mpm, {"output.checkpoint_every=5.0e-5"}), RunOptions{true});
  run(block(wls, {"output.checkpoint_every=5.0e-5", "method.integration=\"wls\""}), RunOptions{true});
  EXPECT_EQ(checkpoint_engine(mpm / "checkpoint-0000.h5"), "mpm");
  EXPECT_EQ(checkpoint_engine(wls / "checkpoint-0000.h5"), "wls");
  const auto again = restore_engine(wls / "checkpoint-0000.h5", {"simulation.end_time=1.5e-4"}, RunOptions{true});
  EXPECT_EQ(again->name(), "wls");
  EXPECT_THROW((void)checkpoint_engine(wls / "no-such-file.h5"), std::runtime_error);
}

TEST(Engines, StopRequestWritesTheAutosaveAndSaysHowToGoOn) {
  const fs::path out = fresh_dir("engine_stop");
  auto engine = make_engine(block(out), RunOptions{true});
  engine->step();
  request_stop(2);  // as SIGINT would
  try {
    engine->step();
    clear_stop_request();
    FAIL() << "no RunInterrupted";
  } catch (const RunInterrupted& e) {
    clear_stop_request();
    EXPECT_NE(std::string(e.what()).find("cairn restart"), std::string::npos) << e.what();
  }
  EXPECT_TRUE(fs::exists(out / "checkpoint-autosave.h5"));
  EXPECT_EQ(engine->step_count(), 2);  // the state is intact: the engine can go on
  engine->step();
  EXPECT_EQ(engine->step_count(), 3);
}

}  // namespace
}  // namespace cairn
