// FEM meshes (Gmsh files and generators, bad meshes rejected with exit 2) and `cairn run` /
// `cairn restart` on an [fem] input.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "cairn/fem/mesh.hpp"
#include "cairn/config/errors.hpp"
#include "fem_case.hpp"

namespace cairn {
namespace {
namespace fs = std::filesystem;

class FemDir : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::temp_directory_path() / ("cairn_fem_" + std::to_string(::getpid()) + "_" + info->name());
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  fs::path write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  /// A Gmsh 2.2 ASCII file of a unit square's four nodes (plus extra nodes) and the given
  /// element lines.
  fs::path msh(const std::string& name, const std::string& elements, int n_elements,
               const std::string& extra_nodes = "", int n_extra = 0) const {
    std::ostringstream s;
    s << "$MeshFormat\n2.2 0 8\n$EndMeshFormat\n$Nodes\n" << 4 + n_extra
      << "\n1 0 0 0\n2 1 0 0\n3 1 1 0\n4 0 1 0\n"
      << extra_nodes << "$EndNodes\n$Elements\n" << n_elements << "\n" << elements << "$EndElements\n";
    return write(name, s.str());
  }
  static std::string read(const fs::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  }
  int cli(const std::string& args) const {
    const std::string cmd = std::string(CAIRN_BINARY) + " " + args + " > " + (dir_ / "log.txt").string() + " 2>&1";
    return WEXITSTATUS(std::system(cmd.c_str()));
  }
  fs::path dir_;
};

/// The InputError message of reading `file`, or "" when it reads fine.
std::string read_error(const fs::path& file) {
  try {
    FemConfig f;
    f.mesh_file = file.string();
    (void)fem::make_mesh(f);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST_F(FemDir, ReadsGmshFileAndDropsBoundaryElementsAndUnusedNodes) {
  // two triangles, one boundary line, one point element, one unused node
  const auto file = msh("ok.msh",
                        "1 15 2 0 1 1\n2 1 2 0 1 1 2\n3 2 2 0 1 1 2 3\n4 2 2 0 1 1 3 4\n", 4, "5 0.5 0.5 0\n", 1);
  FemConfig f;
  f.mesh_file = file.string();
  const fem::TriangleMesh m = fem::make_mesh(f);
  EXPECT_EQ(m.n_nodes(), 4u);
  EXPECT_EQ(m.n_elements(), 2u);
  EXPECT_EQ(m.element_tags[1], 4u);
  for (std::size_t e = 0; e < 2; ++e) EXPECT_NEAR(fem::twice_area(m, e), 1.0, 1e-15);
}

TEST_F(FemDir, ClockwiseMeshIsTurnedRound) {
  const auto file = msh("cw.msh", "1 2 2 0 1 1 3 2\n2 2 2 0 1 1 4 3\n", 2);
  EXPECT_EQ(read_error(file), "");
}

TEST_F(FemDir, RejectsBadMeshesNamingFileElementAndFault) {
  const auto inverted = msh("inverted.msh", "1 2 2 0 1 1 2 3\n2 2 2 0 1 1 4 3\n", 2);
  std::string e = read_error(inverted);
  EXPECT_NE(e.find("inverted.msh"), std::string::npos) << e;
  EXPECT_NE(e.find("element 2 is inverted"), std::string::npos) << e;

  const auto degenerate = msh("degenerate.msh", "1 2 2 0 1 1 2 3\n2 2 2 0 1 1 2 5\n", 2, "5 2 0 0\n", 1);
  e = read_error(degenerate);
  EXPECT_NE(e.find("element 2 is degenerate"), std::string::npos) << e;

  const auto quad = msh("quad.msh", "1 3 2 0 1 1 2 3 4\n", 1);
  e = read_error(quad);
  EXPECT_NE(e.find("quad.msh"), std::string::npos) << e;
  EXPECT_NE(e.find("3-node triangles only"), std::string::npos) << e;
  EXPECT_NE(e.find("Quadrilateral"), std::string::npos) << e;

  const auto second_order = msh("tri6.msh", "1 9 2 0 1 1 2 3 5 6 7\n", 1,
                                "5 1 0.5 0\n6 0.5 0.5 0\n7 0.5 0 0\n", 3);
  e = read_error(second_order);
  EXPECT_NE(e.find("3-node triangles only"), std::string::npos) << e;

  const auto missing = msh("missing.msh", "1 2 2 0 1 1 2 9\n", 1);
  e = read_error(missing);
  EXPECT_NE(e.find("missing.msh"), std::string::npos) << e;
  EXPECT_NE(e.find("9"), std::string::npos) << e;

  const auto empty = msh("lines.msh", "1 1 2 0 1 1 2\n", 1);
  e = read_error(empty);
  EXPECT_NE(e.find("no triangle"), std::string::npos) << e;

  e = read_error(dir_ / "nonexistent.msh");
  EXPECT_NE(e.find("no such file"), std::string::npos) << e;

  const auto garbage = write("garbage.msh", "this is not a mesh\n");
  e = read_error(garbage);
  EXPECT_NE(e.find("garbage.msh"), std::string::npos) << e;
}

TEST_F(FemDir, GeneratedMeshesHaveTheShapeArea) {
  const auto area = [](const std::string& fem) {
    const Config c = test::fem_config(fem);
    const fem::TriangleMesh m = fem::make_mesh(c.fem);
    double a = 0.0;
    for (std::size_t e = 0; e < m.n_elements(); ++e) a += 0.5 * fem::twice_area(m, e);
    return a;
  };
  const double pi = 3.14159265358979323846;
  EXPECT_NEAR(area("shape = { circle = { center = [0.3, 0.3], radius = 0.2 } }\nsize = 0.01\n"), pi * 0.04, 2e-4);
  EXPECT_NEAR(area("shape = { ellipse = { center = [0.0, 0.0], semi_axes = [0.5, 1.0] } }\nsize = 0.02\n"), pi * 0.5,
              3e-3);
  EXPECT_NEAR(area("shape = { annulus = { center = [0.0, 0.0], inner_radius = 0.5, outer_radius = 1.0 } }\n"
                   "size = 0.02\nmesher = \"structured\"\n"),
              pi * 0.75, 2e-3);
  // plate with a hole, quarter model: the hole is centred on the corner
  EXPECT_NEAR(area("shape = { box = { min = [0.0, 0.0], max = [1.0, 1.0] } }\nhole_center = [0.0, 0.0]\n"
                   "hole_radius = 0.5\nsize = 0.02\n"),
              1.0 - pi * 0.25 / 4.0, 1e-3);
}

TEST_F(FemDir, InputErrorsForFemKeys) {
  const auto bad = [](const std::string& fem, const std::string& extra = "") {
    try {
      (void)test::fem_config(fem, extra);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(bad("size = 0.1\n").find("exactly one of fem.mesh_file"), std::string::npos);
  EXPECT_NE(bad("shape = { circle = { center = [0.0, 0.0], radius = 1.0 } }\n").find("fem.size"), std::string::npos);
  EXPECT_NE(bad("shape = { circle = { center = [0.0, 0.0], radius = 1.0 } }\nsize = 0.1\nmesher = \"structured\"\n")
                .find("structured mesher"),
            std::string::npos);
  EXPECT_NE(bad("shape = { box = { min = [0.0, 0.0], max = [1.0, 1.0] } }\nsize = 0.1\n",
                "[grid]\norigin = [0.0, 0.0]\nextent = [1.0, 1.0]\ncell_size = 0.1\n")
                .find("no [grid] in an FEM run"),
            std::string::npos);
  EXPECT_NE(bad("shape = { box = { min = [0.0, 0.0], max = [1.0, 1.0] } }\nsize = 0.1\n", "[method]\nshape = \"linear\"\n")
                .find("no [method] in an FEM run"),
            std::string::npos);
  EXPECT_NE(bad("shape = { box = { min = [0.0, 0.0], max = [1.0, 1.0] } }\nsize = 0.1\nmaterial_x = 1\n")
                .find("material_x"),
            std::string::npos);
}

const char* const case_toml = R"toml(
[simulation]
dimension = 2
end_time = 2.0e-3
cfl = 0.4

[constants]
V = 0.5

[[material]]
name = "rubber"
model = "neo_hookean"
density = 1000.0
youngs_modulus = 1.0e6
poissons_ratio = 0.3

[fem]
material = "rubber"
MESH
velocity = ["V*X", "0"]

[boundary]
x_min = "symmetry"

[[velocity]]
name = "bottom"
face = "y_min"
direction = [0.0, 1.0]
velocity = 0.0

[body_force]
expression = ["0", "-9.81*t/(1e-3 + t)"]

[output]
directory = "OUT"
every = 5.0e-4
checkpoint_every = 1.0e-3
)toml";

std::string fem_case(const std::string& mesh, const fs::path& out) {
  std::string t = case_toml;
  t.replace(t.find("MESH"), 4, mesh);
  t.replace(t.find("OUT"), 3, out.string());
  return t;
}

TEST_F(FemDir, CliRunWritesHistoryXdmfAndRestartsBitIdentically) {
  write("case.toml", fem_case("shape = { box = { min = [0.0, 0.0], max = [0.1, 0.05] } }\nsize = 0.01", dir_ / "out"));
  ASSERT_EQ(cli("check " + (dir_ / "case.toml").string()), 0) << read(dir_ / "log.txt");
  EXPECT_NE(read(dir_ / "log.txt").find("# fem mesh (generated box mesh): "), std::string::npos)
      << read(dir_ / "log.txt");
  ASSERT_EQ(cli("run -q " + (dir_ / "case.toml").string()), 0) << read(dir_ / "log.txt");
  const std::string history = read(dir_ / "out" / "history.csv");
  EXPECT_EQ(history.substr(0, history.find('\n')),
            "time,step,dt,kinetic_energy,strain_energy,external_work,total_energy,energy_error,momentum_x,"
            "momentum_y,momentum_z,max_pressure,reaction_bottom_x,reaction_bottom_y");
  const std::string xdmf = read(dir_ / "out" / "fem.xdmf");
  EXPECT_NE(xdmf.find("TopologyType=\"Triangle\""), std::string::npos);
  EXPECT_NE(xdmf.find("Center=\"Cell\""), std::string::npos);
  EXPECT_TRUE(fs::exists(dir_ / "out" / "snapshots" / "fem-0004.h5"));
  ASSERT_TRUE(fs::exists(dir_ / "out" / "checkpoint-0000.h5"));
  ASSERT_EQ(cli("restart -q " + (dir_ / "out" / "checkpoint-0000.h5").string()), 0) << read(dir_ / "log.txt");
  EXPECT_EQ(read(dir_ / "out" / "history.csv"), history);
}

TEST_F(FemDir, CliRejectsBadMeshWithExitTwo) {
  msh("inverted.msh", "1 2 2 0 1 1 2 3\n2 2 2 0 1 1 4 3\n", 2);
  write("case.toml", fem_case("mesh_file = \"inverted.msh\"", dir_ / "out"));
  EXPECT_EQ(cli("run -q " + (dir_ / "case.toml").string()), 2);
  const std::string log = read(dir_ / "log.txt");
  EXPECT_NE(log.find("inverted.msh"), std::string::npos) << log;
  EXPECT_NE(log.find("fem.mesh_file"), std::string::npos) << log;
  EXPECT_NE(log.find("element 2 is inverted"), std::string::npos) << log;
}

}  // namespace
}  // namespace cairn
