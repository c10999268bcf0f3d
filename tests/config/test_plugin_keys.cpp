// Keys that plug-ins declare beside their code (config/plugin_keys.hpp): they join the schema in
// their section at their place, the validator reads and checks them, the resolved input writes
// them back, and a Config built in code sees their declared defaults.
#include <gtest/gtest.h>

#include <algorithm>
#include <string>
#include <vector>

#include "cairn/config/errors.hpp"
#include "cairn/input/input.hpp"
#include "cairn/input/schema.hpp"
#include "cairn/sim/stress_timing.hpp"

namespace cairn {
namespace {

std::vector<std::string> names_of(const std::string& section) {
  std::vector<std::string> names;
  for (const auto* k : section_keys(section)) names.push_back(k->name);
  return names;
}

const char* input = R"toml(
[simulation]
dimension = 2
end_time = 1.0e-4
[grid]
origin = [0.0, 0.0]
extent = [0.02, 0.01]
cell_size = 1.0e-3
[method]
shape = "ugimp"
smoothing_length = 1.5e-3
update = "blend"
beta = 0.9
[[material]]
name = "rubber"
model = "neo_hookean"
density = 1000.0
youngs_modulus = 1.0e7
poissons_ratio = 0.3
[[body]]
material = "rubber"
shape = { box = { min = [0.004, 0.002], max = [0.012, 0.008] } }
[contact]
law = "general"
slide = "0.2*Nc"
)toml";

TEST(PluginKeys, JoinTheirSectionsWhereTheyBelong) {
  const auto method = names_of("method");
  const std::vector<std::string> head{"shape", "update", "order", "stress_update", "smoothing_length",
                                      "cpdi_max_span", "beta", "blend_position", "position_update"};
  ASSERT_GE(method.size(), head.size());
  EXPECT_EQ(std::vector<std::string>(method.begin(), method.begin() + static_cast<long>(head.size())), head);
  EXPECT_EQ(method.back(), "energy_budget");  // the WLS method's keys close the section
  for (const char* section : {"contact", "contact_pair"}) {
    const auto keys = names_of(section);
    const auto law = std::find(keys.begin(), keys.end(), "law");
    ASSERT_NE(law, keys.end());
    EXPECT_EQ(std::vector<std::string>(law + 1, law + 4),
              (std::vector<std::string>{"friction", "dynamic_friction", "slide"}))
        << section;
  }
  for (const auto* k : section_keys("method"))
    if (k->name == "smoothing_length") {
      EXPECT_EQ(k->owner, "ugimp");
    }
}

TEST(PluginKeys, AreReadCheckedAndWrittenBack) {
  const Config c = load_config_string(input, "case.toml");
  EXPECT_EQ(c.method.plugin.real("smoothing_length"), 1.5e-3);
  EXPECT_EQ(c.method.plugin.real("beta"), 0.9);
  EXPECT_EQ(c.method.plugin.text("blend_position"), "grid");  // the default
  EXPECT_EQ(c.contact.law.plugin.text("slide"), "0.2*Nc");
  EXPECT_EQ(c.contact.law.plugin.real("friction"), 0.0);
  // The resolved input reads back to the same values.
  const Config again = load_config_string(c.resolved_toml, "resolved.toml");
  EXPECT_EQ(again.method.plugin, c.method.plugin);
  EXPECT_EQ(again.contact.law.plugin, c.contact.law.plugin);
  EXPECT_EQ(again.resolved_toml, c.resolved_toml);
  // Ranges, choices, expression variables and the plug-in's own check, with file, line and key.
  auto error = [](const std::vector<std::string>& sets) {
    try {
      (void)load_config_string(input, "case.toml", sets);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error({"method.beta=1.5"}).find("method.beta"), std::string::npos);
  EXPECT_NE(error({"method.blend_position=\"middle\""}).find("grid, projected"), std::string::npos);
  EXPECT_NE(error({"contact.slide=\"2*x\""}).find("one expression in Nc, vslip, t and [constants]"), std::string::npos);
  EXPECT_NE(error({"method.smoothing_length=0.01"}).find("a uGIMP smoothing length of at most twice the smallest "
                                                          "cell size (0.002)"),
            std::string::npos);
}

TEST(PluginKeys, ACodeBuiltConfigSeesTheDeclaredDefaults) {
  const Config c;
  EXPECT_EQ(c.method.plugin.real("cpdi_max_span"), 2.0);
  EXPECT_EQ(c.method.plugin.text("velocity_gradient"), "quadrature");
  EXPECT_FALSE(c.method.plugin.boolean("filter_acceleration"));
  EXPECT_EQ(c.contact.law.plugin.real("dynamic_friction"), -1.0);
  EXPECT_THROW((void)c.method.plugin.real("no_such_key"), std::out_of_range);
}

TEST(StressTimings, SplitEachStepAsSeed003AndSeed002Say) {
  std::vector<std::string> names;
  for (const auto& [name, t] : stress_timings()) {
    names.push_back(name);
    // Every timing updates the stresses by one whole step.
    EXPECT_EQ(t.before_forces + t.with_particle_update + t.after_update, 1.0) << name;
  }
  EXPECT_EQ(names, (std::vector<std::string>{"usl", "usf", "usavg", "usl+", "usavg+"}));
  EXPECT_EQ(stress_timing("usavg").before_forces, 0.5);
  EXPECT_EQ(stress_timing("usavg+").after_update, 0.5);
  EXPECT_THROW((void)stress_timing("usx"), UnknownName);
}

}  // namespace
}  // namespace cairn
