// Crashes, hangs and 32-bit overflows from sizes in the input (issue 16): thread counts, grid and
// particle counts, memory, the number of steps, image sizes. Each refusal must be fast.
#include <array>
#include <chrono>
#include <cstdint>

#include "cairn/grid/grid.hpp"
#include "cairn/materials/material.hpp"
#include "cairn/sim/simulation.hpp"
#include "robustness.hpp"
#include "../support/config_builder.hpp"

namespace cairn::robustness {
namespace {

TEST(Robustness, ThreadCountsAreBoundedAndValidated) {
  const fs::path d = case_dir("threads");
  write_text(d / "case.toml", base_input());
  for (const std::string t : {"100000", "1025", "-1", "two", "1.5"}) {
    const CliResult r = cairn("check case.toml", d);  // the input itself is fine
    ASSERT_EQ(r.code, 0) << r.output;
    const CliResult bad = cairn("run case.toml -q -t " + t, d);
    EXPECT_EQ(bad.code, 2) << "-t " << t << ": " << bad.output;
    EXPECT_NE(bad.output.find("--threads"), std::string::npos) << bad.output;
  }
  // The key: 100000 is out of range, with file, line, key, expected and found.
  EXPECT_TRUE(input_error(cairn_on("check", base_input() + "[output]\n", d, "--set simulation.threads=100000"),
                          "--set simulation.threads=100000", "simulation.threads"));
  std::string text = base_input();
  text.insert(text.find("end_time"), "threads = 100000\n");
  EXPECT_TRUE(input_error(cairn_on("check", text, d), "case.toml:3", "simulation.threads"));
  // Other command-line mistakes are bad input too (CLI11's own codes are 100 and up).
  EXPECT_EQ(cairn("run case.toml --no-such-option", d).code, 2);
  EXPECT_EQ(cairn("run", d).code, 2);
  EXPECT_EQ(cairn("--version", d).code, 0);
  // A valid count runs.
  write_text(d / "case.toml", base_input());
  const CliResult ok = cairn("run case.toml -q -t 3 --set output.directory='\"out\"'", d);
  EXPECT_EQ(ok.code, 0) << ok.output;
  // -t wins over the input's simulation.threads (the summary names the count used).
  text = base_input();
  text.insert(text.find("end_time"), "threads = 1\n");
  write_text(d / "case.toml", text);
  const CliResult cli_wins = cairn("run case.toml -t 3 --set output.directory='\"out\"'", d);
  EXPECT_EQ(cli_wins.code, 0) << cli_wins.output;
  EXPECT_NE(cli_wins.output.find("with 3 threads"), std::string::npos) << cli_wins.output;
  const CliResult file_only = cairn("run case.toml --set output.directory='\"out\"'", d);
  EXPECT_NE(file_only.output.find("with 1 threads"), std::string::npos) << file_only.output;
}

/// Grids whose node count does not fit the 32-bit node index, refused in the loader.
TEST(Robustness, CellCountsAreCheckedIn64Bits) {
  const fs::path d = case_dir("cells");
  struct Case {
    std::string dimension, extent, cell_size;
  };
  const std::array<Case, 5> cases{{
      {"1", "[4294967297.0]", "1.0"},          // 2^32 + 1 cells: was "1 cell"
      {"1", "[1.0e10]", "1.0"},                // was "body contains no particle"
      {"2", "[50000.0, 50000.0]", "1.0"},      // 2.5e9 nodes: was a vector length error
      {"3", "[1.0, 1.0, 1.0]", "1.0e-6"},      // 1e18 cells: looped in particle creation
      {"2", "[1.0, 1.0]", "1.0e-9"},           // 1e9 x 1e9 cells
  }};
  for (const auto& c : cases) {
    const std::string D = c.dimension;
    const std::string zeros = D == "1" ? "[0.0]" : D == "2" ? "[0.0, 0.0]" : "[0.0, 0.0, 0.0]";
    const std::string text = "[simulation]\ndimension = " + D + "\nend_time = 1e-3\n\n[grid]\norigin = " + zeros +
                             "\nextent = " + c.extent + "\ncell_size = " + c.cell_size +
                             "\n\n[[material]]\nname = \"m\"\nmodel = \"linear_elastic\"\ndensity = 1.0\n"
                             "youngs_modulus = 1.0\npoissons_ratio = 0.3\n\n[[body]]\nmaterial = \"m\"\n"
                             "shape = { box = { min = " + zeros + ", max = " +
                             (D == "1" ? "[0.5]" : D == "2" ? "[0.5, 0.5]" : "[0.5, 0.5, 0.5]") + " } }\n";
    const auto start = std::chrono::steady_clock::now();
    const CliResult r = cairn_on("check", text, d);
    EXPECT_TRUE(input_error(r, "case.toml:8", "grid.cell_size")) << c.extent << " / " << c.cell_size;
    EXPECT_NE(r.output.find("32-bit"), std::string::npos) << r.output;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
  }
}

TEST(Robustness, MemoryIsEstimatedBeforeAllocating) {
  const fs::path d = case_dir("memory");
  // ~5e9 particles: 16 x 16 per cell of a 1e4 x 1e4 grid in a 0.44 x 0.44 box.
  std::string text = base_input();
  text.replace(text.find("cell_size = 0.1"), 15, "cell_size = 1e-4");
  text.replace(text.find("max = [0.7, 0.7]"), 16, "max = [0.74, 0.74]");
  text += "particles_per_cell = 16\n";
  CliResult r = cairn_on("check", text, d);
  EXPECT_TRUE(input_error(r, "case.toml:17", "body[0].particles_per_cell"));
  EXPECT_NE(r.output.find("GiB"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("body 'block'"), std::string::npos) << r.output;
  // The limit is a key. A small block fits 1 GiB; on a 1000 x 1000 grid it does not fit 0.01
  // GiB, and the grid's nodes are what is named.
  EXPECT_EQ(cairn_on("check", base_input(), d, "--set simulation.memory_limit=1").code, 0);
  text = base_input();
  text.replace(text.find("cell_size = 0.1"), 15, "cell_size = 1e-3");
  text.replace(text.find("max = [0.7, 0.7]"), 16, "max = [0.31, 0.31]");
  r = cairn_on("check", text, d, "--set simulation.memory_limit=0.01");
  EXPECT_TRUE(input_error(r, "case.toml:8", "grid.cell_size"));
  EXPECT_NE(r.output.find("simulation.memory_limit = 0.01 GiB"), std::string::npos) << r.output;
  EXPECT_EQ(cairn_on("check", text, d, "--set simulation.memory_limit=1").code, 0);
}

// Without simulation.memory_limit, the address space that `ulimit -v` leaves free bounds the
// estimate too, and the message names that limit (issue 36). Not in the sanitizer build: its
// shadow memory needs an unlimited address space.
TEST(Robustness, AddressSpaceLimitBoundsTheEstimate) {
  const fs::path d = case_dir("ulimit");
  std::string text = base_input();  // about 0.65 GiB: 6.4e5 particles and 1e6 nodes
  text.replace(text.find("cell_size = 0.1"), 15, "cell_size = 1e-3");
  write_text(d / "case.toml", text);
  auto check = [&](const std::string& ulimit) {
    const std::string cmd = "cd '" + d.string() + "' && " + ulimit + " OMP_NUM_THREADS=1 '" + CAIRN_BINARY +
                            "' check case.toml > log.txt 2>&1";
    const int status = std::system(("/bin/sh -c \"" + cmd + "\"").c_str());
    return CliResult{WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status), read_text(d / "log.txt")};
  };
  CliResult r = check("ulimit -v 500000 &&");  // KiB: under 0.5 GiB
  EXPECT_TRUE(input_error(r, "case.toml:17", "body[0].particles_per_cell"));
  EXPECT_NE(r.output.find("address-space limit (ulimit -v)"), std::string::npos) << r.output;
  r = check("");
  EXPECT_EQ(r.code, 0) << r.output;
}

/// Particle generation visits the lattice points in the body's bounds, not every grid cell: a
/// small body on a 40000^2-cell grid with 16^2 particles per cell (4e11 lattice points) is quick.
/// (The Grid holds geometry only; nothing is allocated per node here.)
TEST(Robustness, BodyGenerationIsBoundedByTheBodysBounds) {
  Config c = test::box_config(2, "linear");
  c.grid.extent.assign(2, 4000.0);
  const Grid<2> grid(Vec<2>::Zero(), IVec<2>::Constant(40000), Vec<2>::Constant(0.1), 1, {false, false});
  c.bodies[0].shape.min = {1000.0, 2000.0};
  c.bodies[0].shape.max = {1000.5, 2000.3};
  c.bodies[0].particles_per_cell = {16, 16};
  std::vector<std::unique_ptr<Material>> materials;
  materials.push_back(make_material(c.materials[0]));
  Particles<2> particles;
  create_particles<2>(c, grid, materials, Mode::plane_strain, particles);
  // 0.5 / (0.1 / 16) = 80 by 0.3 / (0.1 / 16) = 48 points.
  EXPECT_EQ(particles.n(), 80u * 48u);
  const Vec<2> lo = particles.position.front(), hi = particles.position.back();
  EXPECT_NEAR(lo[0], 1000.0 + 0.5 * 0.1 / 16, 1e-9);
  EXPECT_NEAR(hi[1], 2000.3 - 0.5 * 0.1 / 16, 1e-9);
}

/// The same particles, in the same order, as a sweep of the whole grid gives: a circle, an
/// annulus and a polygon against the lattice points tested one by one.
TEST(Robustness, BoundedGenerationKeepsTheParticlesAndTheirOrder) {
  for (const std::string kind : {"circle", "annulus", "polygon"}) {
    Config c = test::box_config(2, "linear");
    BodyShapeConfig& s = c.bodies[0].shape;
    s.kind = kind;
    s.center = {0.43, 0.52};
    s.radius = 0.21;
    s.inner_radius = 0.1;
    s.outer_radius = 0.3;
    s.vertices = {{0.2, 0.1}, {0.8, 0.3}, {0.4, 0.9}};
    c.bodies[0].particles_per_cell = {3, 2};
    Simulation<2> sim(c);
    const auto& ps = sim.particles();
    std::vector<Vec<2>> expected;
    for (int j = 0; j < 20; ++j)
      for (int i = 0; i < 30; ++i) {
        const Vec<2> X((i + 0.5) * (0.1 / 3), (j + 0.5) * (0.1 / 2));  // as bodies.cpp
        const double r = (X - Vec<2>(0.43, 0.52)).norm();
        bool in = false;
        if (kind == "circle") in = r <= 0.21;
        if (kind == "annulus") in = r >= 0.1 && r <= 0.3;
        if (kind == "polygon") {
          const auto& v = s.vertices;
          for (std::size_t a = 0, b = v.size() - 1; a < v.size(); b = a++)
            if ((v[a][1] > X[1]) != (v[b][1] > X[1]) &&
                X[0] < (v[b][0] - v[a][0]) * (X[1] - v[a][1]) / (v[b][1] - v[a][1]) + v[a][0])
              in = !in;
        }
        if (in) expected.push_back(X);
      }
    ASSERT_EQ(ps.n(), expected.size()) << kind;
    for (std::size_t p = 0; p < ps.n(); ++p) ASSERT_EQ(ps.reference_position[p], expected[p]) << kind << " " << p;
  }
}

TEST(Robustness, RunLengthIsBoundedAndNamesTheMaterial) {
  const fs::path d = case_dir("steps");
  // E = 1e300: wave speed 3e148 m/s, a first step near 1e-150 s: a run that would never end.
  std::string text = base_input();
  text.replace(text.find("youngs_modulus = 1e6"), 20, "youngs_modulus = 1e300");
  const auto start = std::chrono::steady_clock::now();
  CliResult r = cairn_on("run", text, d, "-q");
  EXPECT_TRUE(input_error(r, "case.toml:3", "simulation.end_time"));
  EXPECT_NE(r.output.find("material 'steel' (case.toml:10)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("max_estimated_steps"), std::string::npos) << r.output;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
  // The bound is a key; max_steps bounds the run as well.
  EXPECT_TRUE(input_error(cairn_on("check", base_input(), d, "--set simulation.max_estimated_steps=2"),
                          "case.toml:3", "simulation.end_time"));
  EXPECT_EQ(cairn_on("check", text, d, "--set simulation.max_steps=5").code, 0);
  EXPECT_EQ(cairn_on("check", text, d, "--set simulation.max_estimated_steps=0").code, 0);
  // A fixed dt is named as the cause.
  r = cairn_on("check", base_input(), d, "--set simulation.dt=1e-12");
  EXPECT_NE(r.output.find("simulation.dt = 1e-12 sets the step"), std::string::npos) << r.output;
}

/// CRC-32 of a PNG chunk's type and data (ISO 3309 polynomial, as PNG requires).
std::uint32_t crc32(const std::string& bytes) {
  std::uint32_t c = 0xFFFFFFFFu;
  for (unsigned char b : bytes) {
    c ^= b;
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xEDB88320u & (0u - (c & 1u)));
  }
  return c ^ 0xFFFFFFFFu;
}

std::string be32(std::uint32_t v) {
  return {static_cast<char>(v >> 24), static_cast<char>(v >> 16), static_cast<char>(v >> 8), static_cast<char>(v)};
}

TEST(Robustness, HugePngHeaderIsAnInputErrorAtTheImageKey) {
  const fs::path d = case_dir("png");
  // A valid signature, an IHDR claiming 1e6 x 1e6 8-bit grey pixels, a few bytes of IDAT, IEND.
  const auto chunk = [](const std::string& type_and_data) {
    return be32(static_cast<std::uint32_t>(type_and_data.size() - 4)) + type_and_data + be32(crc32(type_and_data));
  };
  write_text(d / "huge.png", std::string("\x89PNG\r\n\x1a\n", 8) +
                                 chunk("IHDR" + be32(1000000) + be32(1000000) + std::string("\x08\x00\x00\x00\x00", 5)) +
                                 chunk(std::string("IDAT\x78\x9c\x63\x00\x00", 9)) + chunk("IEND"));
  std::string text = base_input();
  text.replace(text.find("shape = { box"), text.find('\n', text.find("shape = { box")) - text.find("shape = { box"),
               "shape = { image = { file = \"huge.png\", pixel_size = 1e-3, origin = [0.0, 0.0], levels = [0, 100] } }");
  const CliResult r = cairn_on("check", text, d);
  EXPECT_TRUE(input_error(r, "case.toml:20", "body[0].shape.image.file"));
  EXPECT_NE(r.output.find("1000000 x 1000000 pixels"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace cairn::robustness
