// Inputs that used to run to a wrong answer without a word, and messages without a location
// (issue 16): clipped and overlapping bodies, muParser's comma and assignment, t in an initial
// value, extreme physical values, and the key of every expression and body error.
#include "cairn/bc/expression.hpp"
#include "robustness.hpp"

namespace cairn::robustness {
namespace {

std::string with_box(const std::string& min, const std::string& max) {
  std::string text = base_input();
  text.replace(text.find("min = [0.3, 0.3], max = [0.7, 0.7]"), 34, "min = " + min + ", max = " + max);
  return text;
}

TEST(Robustness, BodyPastTheGridIsAnErrorUnlessClipped) {
  const fs::path d = case_dir("clip");
  const std::string text = with_box("[0.3, 0.3]", "[1.3, 0.7]");
  CliResult r = cairn_on("check", text, d);
  EXPECT_TRUE(input_error(r, "case.toml:17", "body[0].shape"));
  EXPECT_NE(r.output.find("clip = true"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("max face on axis x"), std::string::npos) << r.output;
  // Opting in keeps the part inside: 0.7 x 0.4 of the grid at 2 x 2 per 0.1 cell.
  r = cairn_on("check", text + "clip = true\n", d);
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("# body 'block': 112 particles"), std::string::npos) << r.output;
  // Less than half a particle spacing past a face loses no particle and is fine.
  EXPECT_EQ(cairn_on("check", with_box("[-0.02, 0.3]", "[0.7, 1.02]"), d).code, 0);
  EXPECT_TRUE(input_error(cairn_on("check", with_box("[-0.03, 0.3]", "[0.7, 0.7]"), d), "case.toml:17",
                          "body[0].shape"));
}

TEST(Robustness, OverlappingBodiesAreAnErrorOrAWarning) {
  const fs::path d = case_dir("overlap");
  const std::string second =
      "[[body]]\nname = \"plug\"\nmaterial = \"steel\"\n"  // line 22 of the input
      "shape = { circle = { center = [0.7, 0.5], radius = 0.1 } }\n";
  CliResult r = cairn_on("check", base_input() + second, d);
  EXPECT_TRUE(input_error(r, "case.toml:22", "body[1].shape"));
  EXPECT_NE(r.output.find("bodies 'block' (case.toml:17) and 'plug' (case.toml:22) overlap"), std::string::npos)
      << r.output;
  r = cairn_on("check", base_input() + second, d, "--set simulation.body_overlap='\"warn\"'");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: bodies 'block' (case.toml:17) and 'plug' (case.toml:22) overlap"),
            std::string::npos)
      << r.output;
  // Touching is not overlapping.
  const std::string beside = "[[body]]\nname = \"beside\"\nmaterial = \"steel\"\n"
                             "shape = { box = { min = [0.7, 0.3], max = [0.9, 0.7] } }\n";
  EXPECT_EQ(cairn_on("check", base_input() + beside, d).code, 0);
}

TEST(Robustness, ExpressionsRejectCommaAndAssignment) {
  // The class itself refuses them, whoever builds it.
  const Constants none;
  EXPECT_THROW(Expression("-9,81", none), std::invalid_argument);
  EXPECT_THROW(Expression("t=1e9", none), std::invalid_argument);
  EXPECT_THROW(Expression("x += 1", none), std::invalid_argument);
  EXPECT_NO_THROW(Expression("min(t, 2) + tri(t, 1) * (x <= 1) + (y >= 2) + (t == 0) + (t != 1)", none));

  const fs::path d = case_dir("expressions");
  const std::string force = "[body_force]\nexpression = [0.0, \"-9,81\"]\n";  // lines 22-23
  CliResult r = cairn_on("check", base_input() + force, d);
  EXPECT_TRUE(input_error(r, "case.toml:23", "body_force.expression[1]"));
  EXPECT_NE(r.output.find("','"), std::string::npos) << r.output;
  r = cairn_on("check", base_input() + "[body_force]\nexpression = [0.0, \"t=1e9\"]\n", d);
  EXPECT_TRUE(input_error(r, "case.toml:23", "body_force.expression[1]"));
  EXPECT_NE(r.output.find("assignment"), std::string::npos) << r.output;
  // The contact law's slide expression has its own variables and the same rules.
  r = cairn_on("check", base_input() + "[contact]\nmode = \"body\"\nlaw = \"general\"\nslide = \"vslip, 1\"\n", d);
  EXPECT_TRUE(input_error(r, "case.toml:25", "contact.slide"));
  // A syntax error names file, line and key (it used to give muParser's message alone).
  r = cairn_on("check", base_input() + "[body_force]\nexpression = [0.0, \"-9.81*(\"]\n", d);
  EXPECT_TRUE(input_error(r, "case.toml:23", "body_force.expression[1]"));
}

TEST(Robustness, TimeIsRejectedWhereItIsMeaningless) {
  const fs::path d = case_dir("initial_t");
  CliResult r = cairn_on("check", base_input() + "velocity = [\"2 * t\", 0.0]\n", d);
  EXPECT_TRUE(input_error(r, "case.toml:22", "body[0].velocity[0]"));
  EXPECT_NE(r.output.find("does not depend on time"), std::string::npos) << r.output;
  r = cairn_on("check", base_input() + "displacement = [0.0, \"Z\"]\n", d);
  EXPECT_TRUE(input_error(r, "case.toml:22", "body[0].displacement[1]"));
  EXPECT_NE(r.output.find("a 2D input has no Z axis"), std::string::npos) << r.output;
  EXPECT_EQ(cairn_on("check", base_input() + "velocity = [\"X - 0.5\", \"y\"]\n", d).code, 0);
  // A time function with a position, and a wall velocity with a syntax error: file, line, key.
  r = cairn_on("check", base_input() + "[[velocity]]\nface = \"x_min\"\ndirection = [1.0, 0.0]\nvelocity = \"x\"\n", d);
  EXPECT_TRUE(input_error(r, "case.toml:25", "velocity[0].velocity"));
  EXPECT_NE(r.output.find("has no position"), std::string::npos) << r.output;
  r = cairn_on("check", base_input() + "[[wall]]\naxis = \"x\"\ninside = \"below\"\nposition = 0.9\nvelocity = \"-9.81*(\"\n", d);
  EXPECT_TRUE(input_error(r, "case.toml:26", "wall[0].velocity"));
}

TEST(Robustness, ExtremePhysicalValuesWarn) {
  const fs::path d = case_dir("extreme");
  std::string text = base_input();
  text.replace(text.find("density = 1000.0"), 16, "density = 1e308");
  const CliResult r = cairn_on("check", text, d);
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("warning: case.toml:13: key 'material[0].density': 1e+308 is beyond 1e30"),
            std::string::npos)
      << r.output;
  EXPECT_EQ(cairn_on("check", base_input(), d).output.find("warning"), std::string::npos);
  // A restart prints the warnings of its input as a run does.
  const CliResult run = cairn_on("run", text, d, "-q --set output.checkpoint_every=5e-3 --set output.directory='\"out\"'");
  ASSERT_EQ(run.code, 0) << run.output;
  // (one step reaches the end here: the restart goes on to a later end time)
  const CliResult again = cairn("restart out/checkpoint-0000.h5 -q --set simulation.end_time=2e-2", d);
  EXPECT_EQ(again.code, 0) << again.output;
  EXPECT_NE(again.output.find("key 'material[0].density': 1e+308 is beyond 1e30"), std::string::npos) << again.output;
}

TEST(Robustness, EmptySelectionsNameKeyExpectedAndFound) {
  const fs::path d = case_dir("empty_selection");
  // A plane between the nodes, and a box around no particle face.
  CliResult r = cairn_on("check", base_input() + "[[velocity]]\nplane_axis = \"x\"\nplane_at = 0.55\n"
                                                 "direction = [1.0, 0.0]\n", d);
  EXPECT_TRUE(input_error(r, "case.toml:22", "velocity[0]"));
  r = cairn_on("check", base_input() + "[[traction]]\nbox_min = [0.0, 0.0]\nbox_max = [0.1, 0.1]\n"
                                       "traction = [1.0, 0.0]\n", d);
  EXPECT_TRUE(input_error(r, "case.toml:22", "traction[0]"));
}

TEST(Robustness, BodyWithoutParticlesNamesKeyExpectedAndFound) {
  const fs::path d = case_dir("no_particle");
  // A box thinner than the particle spacing between two lattice rows.
  const CliResult r = cairn_on("check", with_box("[0.3, 0.301]", "[0.7, 0.302]"), d);
  EXPECT_TRUE(input_error(r, "case.toml:17", "body[0].shape"));
  EXPECT_NE(r.output.find("hold no lattice point"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace cairn::robustness
