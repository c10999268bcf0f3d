// Tests of the output layer: atomic writes, history CSV, HDF5/XDMF snapshots, checkpoints.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <hdf5.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "cairn/io/atomic_file.hpp"
#include "cairn/io/checkpoint.hpp"
#include "cairn/io/hdf5_util.hpp"
#include "cairn/io/history.hpp"
#include "cairn/io/output_schedule.hpp"
#include "cairn/io/snapshot.hpp"
#include "cairn/config/units.hpp"
#include "cairn/util/sha256.hpp"

namespace fs = std::filesystem;
using namespace cairn;

namespace {

/// A fresh, empty directory for one test, removed afterwards.
class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    std::string name = std::string(info->test_suite_name()) + "_" + info->name();
    for (char& c : name)
      if (c == '/') c = '_';
    path_ = fs::temp_directory_path() / ("cairn_io_" + std::to_string(::getpid()) + "_" + name);
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

std::string read_all(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> list_dir(const fs::path& dir) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(dir)) names.push_back(e.path().filename().string());
  std::sort(names.begin(), names.end());
  return names;
}

bool same_bits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

template <typename T>
bool same_bits(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

template <int D>
Particles<D> random_particles(std::size_t n, int n_state, std::mt19937_64& rng) {
  std::uniform_real_distribution<double> u(-1.0e3, 1.0e3);
  std::uniform_int_distribution<int> k(-5, 40);
  Particles<D> ps;
  ps.n_state_per_particle = n_state;
  ps.resize(n);
  auto vec = [&] {
    Vec<D> v;
    for (int a = 0; a < D; ++a) v[a] = u(rng);
    return v;
  };
  auto mat = [&] {
    Mat3 m;
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) m(i, j) = u(rng);
    return m;
  };
  for (std::size_t p = 0; p < n; ++p) {
    ps.position[p] = vec();
    ps.reference_position[p] = vec();
    ps.velocity[p] = vec();
    ps.mass[p] = std::abs(u(rng)) * 1e-7;
    ps.volume0[p] = std::abs(u(rng)) * 1e-12;
    ps.size0[p] = vec();
    ps.deformation_gradient[p] = mat();
    ps.kirchhoff_stress[p] = mat() * 1e9;
    ps.affine_velocity[p] = mat();
    ps.temperature[p] = 300.0 + u(rng);
    ps.material[p] = k(rng);
    ps.body[p] = k(rng);
  }
  for (double& s : ps.state) s = u(rng) / 7.0;
  if (n > 0) {  // awkward values that must survive exactly
    ps.position[0][0] = -0.0;
    ps.mass[0] = std::numeric_limits<double>::denorm_min();
    ps.kirchhoff_stress[0](1, 2) = std::numeric_limits<double>::max();
    ps.affine_velocity[0](2, 0) = std::numeric_limits<double>::infinity();
  }
  return ps;
}

template <int D>
void expect_vecs_identical(const std::vector<Vec<D>>& a, const std::vector<Vec<D>>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t p = 0; p < a.size(); ++p)
    for (int i = 0; i < D; ++i) EXPECT_TRUE(same_bits(a[p][i], b[p][i])) << what << " particle " << p;
}

void expect_mats_identical(const std::vector<Mat3>& a, const std::vector<Mat3>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t p = 0; p < a.size(); ++p) {
    EXPECT_TRUE(a[p] == b[p]) << what << " particle " << p;
    for (int i = 0; i < 9; ++i) EXPECT_TRUE(same_bits(a[p].data()[i], b[p].data()[i])) << what;
  }
}

void expect_mats_identical(const std::vector<SymMat3>& a, const std::vector<SymMat3>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t p = 0; p < a.size(); ++p)
    for (int k = 0; k < 6; ++k) EXPECT_TRUE(same_bits(a[p].voigt()[k], b[p].voigt()[k])) << what << " particle " << p;
}

template <int D>
void expect_particles_identical(const Particles<D>& a, const Particles<D>& b) {
  EXPECT_EQ(a.n_state_per_particle, b.n_state_per_particle);
  expect_vecs_identical<D>(a.position, b.position, "position");
  expect_vecs_identical<D>(a.reference_position, b.reference_position, "reference_position");
  expect_vecs_identical<D>(a.velocity, b.velocity, "velocity");
  expect_vecs_identical<D>(a.size0, b.size0, "size0");
  EXPECT_TRUE(same_bits(a.mass, b.mass));
  EXPECT_TRUE(same_bits(a.volume0, b.volume0));
  EXPECT_TRUE(a.mass == b.mass);
  expect_mats_identical(a.deformation_gradient, b.deformation_gradient, "F");
  expect_mats_identical(a.kirchhoff_stress, b.kirchhoff_stress, "tau");
  expect_mats_identical(a.affine_velocity, b.affine_velocity, "C");
  EXPECT_TRUE(same_bits(a.temperature, b.temperature));
  EXPECT_EQ(a.material, b.material);
  EXPECT_EQ(a.body, b.body);
  EXPECT_TRUE(a.state == b.state);
  EXPECT_TRUE(same_bits(a.state, b.state));
}

template <typename Dim>
class CheckpointTest : public ::testing::Test {};
using Dims = ::testing::Types<std::integral_constant<int, 1>, std::integral_constant<int, 2>,
                              std::integral_constant<int, 3>>;
TYPED_TEST_SUITE(CheckpointTest, Dims);

}  // namespace

// ---------------------------------------------------------------------------------------------
// Atomic writes

TEST(AtomicFile, WriteLeavesNoTempFile) {
  TempDir dir;
  const fs::path target = dir.path() / "sub" / "a.txt";
  write_text_atomically(target, "hello\n");
  EXPECT_EQ(read_all(target), "hello\n");
  write_text_atomically(target, "second");
  EXPECT_EQ(read_all(target), "second");
  EXPECT_EQ(list_dir(target.parent_path()), std::vector<std::string>{"a.txt"});
}

TEST(AtomicFile, TempFileIsNewAndNextToTarget) {
  TempDir dir;
  const fs::path target = dir.path() / "file.h5";
  const fs::path a = create_atomic_temp(target), b = create_atomic_temp(target);
  EXPECT_EQ(a.parent_path(), dir.path());
  EXPECT_EQ(a.filename().string().rfind("file.h5.tmp." + std::to_string(::getpid()) + ".", 0), 0u);
  EXPECT_NE(a, b);
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(a)));
}

TEST(AtomicFile, ExceptionKeepsOldTarget) {
  TempDir dir;
  const fs::path target = dir.path() / "b.txt";
  write_text_atomically(target, "old contents");
  EXPECT_THROW(write_file_atomically(target,
                                     [](const fs::path& tmp) {
                                       std::ofstream(tmp) << "partial new con";
                                       throw std::runtime_error("disk on fire");
                                     }),
               std::runtime_error);
  EXPECT_EQ(read_all(target), "old contents");
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"b.txt"});
}

TEST(AtomicFile, ExceptionWithoutTargetCreatesNothing) {
  TempDir dir;
  const fs::path target = dir.path() / "c.txt";
  EXPECT_THROW(write_file_atomically(target, [](const fs::path&) { throw std::logic_error("x"); }),
               std::logic_error);
  EXPECT_TRUE(list_dir(dir.path()).empty());
}

// ---------------------------------------------------------------------------------------------
// History

TEST(History, FlushWritesHeaderAndRows) {
  TempDir dir;
  const fs::path path = dir.path() / "history.csv";
  HistoryWriter h(path, {"kinetic_energy", "momentum_x"});
  EXPECT_EQ(h.columns(), (std::vector<std::string>{"time", "step", "dt", "kinetic_energy", "momentum_x"}));
  h.flush();
  EXPECT_EQ(read_all(path), "time,step,dt,kinetic_energy,momentum_x\n");
  h.add_row({0.0, 0.0, 0.0, 0.5, -2.0});
  h.add_row(0.1, 3, 1e-5, {1.0 / 3.0, 1e300});
  h.flush();
  EXPECT_EQ(read_all(path),
            "time,step,dt,kinetic_energy,momentum_x\n"
            "0,0,0,0.5,-2\n"
            "0.10000000000000001,3,1.0000000000000001e-05,0.33333333333333331,1.0000000000000001e+300\n");
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"history.csv"});
}

TEST(History, RowsRoundTripThroughSetRows) {
  TempDir dir;
  HistoryWriter a(dir.path() / "a.csv", {"e"});
  for (int i = 0; i < 5; ++i) a.add_row(0.1 * i, i, 0.1, {std::sqrt(i + 0.5)});
  HistoryWriter b(dir.path() / "b.csv", a.columns());  // full column list is accepted as well
  EXPECT_EQ(b.columns(), a.columns());
  b.set_rows(a.rows());
  EXPECT_EQ(b.csv_text(), a.csv_text());
  a.add_row(0.5, 5, 0.1, {7.0});
  b.add_row(0.5, 5, 0.1, {7.0});
  a.flush();
  b.flush();
  EXPECT_EQ(read_all(dir.path() / "a.csv"), read_all(dir.path() / "b.csv"));
}

TEST(History, RejectsWrongRowLength) {
  HistoryWriter h("unused.csv", {"e", "f"});
  EXPECT_THROW(h.add_row({1.0, 2.0, 3.0}), std::invalid_argument);
  EXPECT_THROW(h.set_rows({{1.0, 2.0, 3.0, 4.0}}), std::invalid_argument);
  EXPECT_THROW(HistoryWriter("x.csv", {"bad,name"}), std::invalid_argument);
}

// ---------------------------------------------------------------------------------------------
// Checkpoints

TYPED_TEST(CheckpointTest, RoundTripIsBitIdentical) {
  constexpr int D = TypeParam::value;
  TempDir dir;
  std::mt19937_64 rng(1234 + D);
  CheckpointData<D> data;
  data.config_toml = "[simulation]\ndimension = 2\ntitle = \"quoted \\\"text\\\" with ünïcode\"\n";
  data.time = 1.0 / 3.0;
  data.step = 123456789012LL;
  data.previous_dt = 2.0e-7 / 3.0;
  data.scalars = {{"external_work", -4.0 / 7.0}, {"next_snapshot_time", 0.25}, {"a b", 1e-300}};
  data.history_columns = {"time", "step", "dt", "kinetic_energy"};
  for (int r = 0; r < 4; ++r) data.history_rows.push_back({r * 0.1, double(r), 0.1 / 3.0, std::exp(r * 1.1)});
  data.snapshot_entries = {{0.0, "particles-000000.h5"}, {0.1 / 3.0, "particles-000001.h5"}};
  data.snapshot_next_index = 2;
  data.contact_record = {7, 3, 7, 1LL << 40};  // [contact] release = "separation"; any order, repeats
  data.particles = random_particles<D>(37, 3, rng);

  const fs::path path = dir.path() / "checkpoint.h5";
  write_checkpoint<D>(path, data);
  EXPECT_EQ(list_dir(dir.path()), std::vector<std::string>{"checkpoint.h5"});
  EXPECT_EQ(checkpoint_dimension(path), D);

  const CheckpointData<D> back = read_checkpoint<D>(path);
  EXPECT_EQ(back.config_toml, data.config_toml);
  EXPECT_TRUE(same_bits(back.time, data.time));
  EXPECT_EQ(back.step, data.step);
  EXPECT_TRUE(same_bits(back.previous_dt, data.previous_dt));
  EXPECT_EQ(back.scalars, data.scalars);
  EXPECT_EQ(back.history_columns, data.history_columns);
  EXPECT_EQ(back.history_rows, data.history_rows);
  EXPECT_EQ(back.snapshot_entries, data.snapshot_entries);
  EXPECT_EQ(back.snapshot_next_index, data.snapshot_next_index);
  EXPECT_EQ(back.contact_record, data.contact_record);
  expect_particles_identical<D>(back.particles, data.particles);

  // Writing what was read gives the same checkpoint again.
  const fs::path again = dir.path() / "again.h5";
  write_checkpoint<D>(again, back);
  expect_particles_identical<D>(read_checkpoint<D>(again).particles, data.particles);
}

TYPED_TEST(CheckpointTest, EmptyStateRoundTrips) {
  constexpr int D = TypeParam::value;
  TempDir dir;
  CheckpointData<D> data;  // no particles, no history, no snapshots, empty config
  const fs::path path = dir.path() / "empty.h5";
  write_checkpoint<D>(path, data);
  const CheckpointData<D> back = read_checkpoint<D>(path);
  EXPECT_EQ(back.config_toml, "");
  EXPECT_EQ(back.particles.n(), 0u);
  EXPECT_EQ(back.particles.n_state_per_particle, 0);
  EXPECT_TRUE(back.history_rows.empty());
  EXPECT_TRUE(back.history_columns.empty());
  EXPECT_TRUE(back.snapshot_entries.empty());
  EXPECT_TRUE(back.scalars.empty());
  EXPECT_TRUE(back.contact_record.empty());
}

TEST(Checkpoint, WrongDimensionThrows) {
  TempDir dir;
  CheckpointData<3> data;
  const fs::path path = dir.path() / "c3.h5";
  write_checkpoint<3>(path, data);
  try {
    (void)read_checkpoint<2>(path);
    FAIL() << "expected an exception";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("3D"), std::string::npos) << e.what();
  }
}

TEST(Checkpoint, NonCheckpointFilesThrowClearly) {
  TempDir dir;
  auto expect_message = [](const fs::path& p, const std::string& needle) {
    try {
      (void)read_checkpoint<2>(p);
      ADD_FAILURE() << "expected an exception for " << p;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << e.what();
    }
    EXPECT_THROW((void)checkpoint_dimension(p), std::runtime_error);
  };

  expect_message(dir.path() / "missing.h5", "does not exist");

  const fs::path text = dir.path() / "input.toml";
  write_text_atomically(text, "[simulation]\ndimension = 2\n");
  expect_message(text, "not a Cairn checkpoint");

  // A valid HDF5 file, but a snapshot rather than a checkpoint.
  SnapshotWriter<2> snapshots(dir.path());
  Particles<2> ps;
  ps.add(Vec<2>(0.5, 0.5), Vec<2>(1.0, 0.0), 1.0, 1.0, Vec<2>(0.5, 0.5), 0, 0);
  snapshots.write(ps, 0.0, 0);
  expect_message(snapshots.snapshot_path(0), "not a Cairn checkpoint");

  // An HDF5 file with no attributes at all.
  const fs::path bare = dir.path() / "bare.h5";
  { h5::Handle f = h5::create_file(bare); }
  expect_message(bare, "not a Cairn checkpoint");

  // A checkpoint of a future format version.
  const fs::path future = dir.path() / "future.h5";
  write_checkpoint<2>(future, CheckpointData<2>{});
  {
    h5::Handle f(H5Fopen(future.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    ASSERT_GE(f.get(), 0);
    h5::write_int64_attribute(f.get(), "version", checkpoint_format_version + 1);
  }
  expect_message(future, fmt::format("version {}", checkpoint_format_version + 1));
}

TEST(Checkpoint, InconsistentParticlesRejected) {
  TempDir dir;
  CheckpointData<2> data;
  data.particles.add(Vec<2>(0, 0), Vec<2>(0, 0), 1, 1, Vec<2>(1, 1), 0, 0);
  data.particles.mass.push_back(2.0);
  EXPECT_THROW(write_checkpoint<2>(dir.path() / "bad.h5", data), std::invalid_argument);
  EXPECT_TRUE(list_dir(dir.path()).empty());
}

// ---------------------------------------------------------------------------------------------
// Snapshots

TEST(Snapshot, WritesParticlesAndXdmf) {
  TempDir dir;
  Particles<2> ps;
  ps.add(Vec<2>(0.1, 0.2), Vec<2>(1.0, -2.0), 3.0, 0.5, Vec<2>(0.1, 0.1), 1, 4);
  ps.add(Vec<2>(0.3, 0.4), Vec<2>(0.0, 0.0), 5.0, 0.25, Vec<2>(0.1, 0.1), 0, 2);
  ps.position[0] = Vec<2>(0.15, 0.1);
  ps.deformation_gradient[0] = Eigen::Vector3d(2.0, 1.0, 1.0).asDiagonal();
  ps.kirchhoff_stress[0] = Eigen::Vector3d(4.0, 2.0, 2.0).asDiagonal();  // sigma = diag(2, 1, 1)
  ps.kirchhoff_stress[0](0, 1) = ps.kirchhoff_stress[0](1, 0) = 6.0;    // sigma_xy = 3

  SnapshotWriter<2> writer(dir.path());
  EXPECT_EQ(writer.next_index(), 0);
  writer.write(ps, 0.0, 0);
  writer.write(ps, 0.5, 10);
  EXPECT_EQ(writer.next_index(), 2);
  ASSERT_EQ(writer.entries().size(), 2u);
  EXPECT_EQ(writer.entries()[1], (std::pair<double, std::string>(0.5, "particles-000001.h5")));
  EXPECT_EQ(list_dir(dir.path()), (std::vector<std::string>{"particles.xdmf", "snapshots"}));
  EXPECT_EQ(list_dir(dir.path() / "snapshots"),
            (std::vector<std::string>{"particles-000000.h5", "particles-000001.h5"}));

  const std::string xdmf = read_all(writer.particles_xdmf_path());
  EXPECT_NE(xdmf.find("CollectionType=\"Temporal\""), std::string::npos);
  EXPECT_NE(xdmf.find("snapshots/particles-000000.h5:/particles/position"), std::string::npos);
  EXPECT_NE(xdmf.find("snapshots/particles-000001.h5:/particles/stress"), std::string::npos);
  EXPECT_NE(xdmf.find("TopologyType=\"Polyvertex\" NumberOfElements=\"2\""), std::string::npos);
  EXPECT_NE(xdmf.find("<Time Value=\"0.5\"/>"), std::string::npos);

  h5::Handle f = h5::open_file(writer.snapshot_path(1));
  EXPECT_EQ(h5::read_double_attribute(f.get(), "time"), 0.5);
  EXPECT_EQ(h5::read_int64_attribute(f.get(), "step"), 10);
  EXPECT_EQ(h5::read_int64_attribute(f.get(), "dimension"), 2);
  h5::Handle g = h5::open_group(f.get(), "particles");
  const auto pos = h5::read_doubles(g.get(), "position", {2, 3});
  EXPECT_EQ(pos, (std::vector<double>{0.15, 0.1, 0.0, 0.3, 0.4, 0.0}));
  const auto disp = h5::read_doubles(g.get(), "displacement", {2, 3});
  EXPECT_DOUBLE_EQ(disp[0], 0.05);
  EXPECT_DOUBLE_EQ(disp[1], -0.1);
  EXPECT_EQ(h5::read_doubles(g.get(), "mass", {2}), (std::vector<double>{3.0, 5.0}));
  EXPECT_EQ(h5::read_doubles(g.get(), "volume", {2}), (std::vector<double>{1.0, 0.25}));
  const auto stress = h5::read_doubles(g.get(), "stress", {2, 6});
  EXPECT_EQ(std::vector<double>(stress.begin(), stress.begin() + 6),
            (std::vector<double>{2.0, 1.0, 1.0, 3.0, 0.0, 0.0}));  // xx yy zz xy yz xz
  EXPECT_DOUBLE_EQ(h5::read_doubles(g.get(), "pressure", {2})[0], -4.0 / 3.0);
  EXPECT_DOUBLE_EQ(h5::read_doubles(g.get(), "von_mises", {2})[0], std::sqrt(1.0 + 27.0));
  const auto F = h5::read_doubles(g.get(), "deformation_gradient", {2, 9});
  EXPECT_EQ(std::vector<double>(F.begin(), F.begin() + 9),
            (std::vector<double>{2, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_EQ(h5::read_ints(g.get(), "material", 2), (std::vector<std::int32_t>{1, 0}));
  EXPECT_EQ(h5::read_ints(g.get(), "body", 2), (std::vector<std::int32_t>{4, 2}));
}

TEST(Snapshot, GridDataAndGridXdmf) {
  TempDir dir;
  // 4 x 2 cells, h = (0.5, 0.25), one ghost layer, y periodic.
  Grid<2> grid(Vec<2>(1.0, 2.0), IVec<2>(4, 2), Vec<2>(0.5, 0.25), 1, {false, true});
  ASSERT_EQ(grid.stored_nodes(0), 7);
  ASSERT_EQ(grid.stored_nodes(1), 2);
  NodeField<2> nodes;
  nodes.resize(grid.n_nodes());
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
    nodes.mass[i] = i;
    nodes.velocity_new[i] = Vec<2>(i, -i);
  }
  Particles<2> ps;
  ps.add(Vec<2>(1.5, 2.1), Vec<2>(0, 0), 1.0, 1.0, Vec<2>(0.25, 0.125), 0, 0);
  SnapshotWriter<2> writer(dir.path());
  writer.write(ps, 0.0, 0, &grid, &nodes);
  ASSERT_TRUE(fs::exists(writer.grid_xdmf_path()));
  EXPECT_EQ(writer.grid_xdmf_path(), dir.path() / "grid.xdmf");
  // The domain nodes only (5 x 3: no ghost layer in x, the periodic y axis repeats its first
  // node row), as a 3D mesh one node thick in z, in the x-y plane (origin and spacing z y x).
  const std::string xdmf = read_all(writer.grid_xdmf_path());
  EXPECT_NE(xdmf.find("TopologyType=\"3DCoRectMesh\" Dimensions=\"1 3 5\""), std::string::npos) << xdmf;
  EXPECT_NE(xdmf.find(">0 2 1</DataItem>"), std::string::npos) << xdmf;       // origin z y x
  EXPECT_NE(xdmf.find(">1 0.25 0.5</DataItem>"), std::string::npos) << xdmf;  // spacing z y x
  EXPECT_NE(xdmf.find("Dimensions=\"1 3 5 3\" NumberType=\"Float\" Precision=\"8\" Format=\"HDF\">"
                      "snapshots/particles-000000.h5:/grid/node_velocity"),
            std::string::npos) << xdmf;

  h5::Handle f = h5::open_file(writer.snapshot_path(0));
  h5::Handle g = h5::open_group(f.get(), "grid");
  EXPECT_EQ(h5::dataset_shape(g.get(), "node_mass"), (std::vector<std::size_t>{3, 5}));
  const auto mass = h5::read_doubles(g.get(), "node_mass", {3, 5});
  // Stored node index = (jx + 1) + 7 (jy mod 2): one ghost layer in x, y periodic.
  EXPECT_EQ(mass, (std::vector<double>{1, 2, 3, 4, 5, 8, 9, 10, 11, 12, 1, 2, 3, 4, 5}));
  const auto vel = h5::read_doubles(g.get(), "node_velocity", {3, 5, 3});
  EXPECT_EQ(vel[3 * 7 + 0], 10.0);  // node (jx, jy) = (2, 1)
  EXPECT_EQ(vel[3 * 7 + 1], -10.0);
  EXPECT_EQ(vel[3 * 7 + 2], 0.0);
  EXPECT_EQ(h5::read_doubles_attribute(g.get(), "origin"), (std::vector<double>{1.0, 2.0, 0.0}));
  EXPECT_EQ(h5::read_doubles_attribute(g.get(), "spacing"), (std::vector<double>{0.5, 0.25, 1.0}));
}

TEST(Snapshot, OtherDimensionsWrite) {
  TempDir dir;
  {
    Grid<1> grid(Vec<1>(0.0), IVec<1>(3), Vec<1>(1.0), 2, {false});
    NodeField<1> nodes;
    nodes.resize(grid.n_nodes());
    Particles<1> ps;
    ps.add(Vec<1>(0.5), Vec<1>(1.0), 1.0, 1.0, Vec<1>(0.5), 0, 0);
    SnapshotWriter<1> writer(dir.path() / "d1");
    writer.write(ps, 0.0, 0, &grid, &nodes);
    EXPECT_NE(read_all(writer.grid_xdmf_path()).find("Dimensions=\"1 1 4\""), std::string::npos);
    h5::Handle f = h5::open_file(writer.snapshot_path(0));
    h5::Handle g = h5::open_group(f.get(), "particles");
    EXPECT_EQ(h5::read_doubles(g.get(), "velocity", {1, 3}), (std::vector<double>{1.0, 0.0, 0.0}));
  }
  {
    Grid<3> grid(Vec<3>(0, 0, 0), IVec<3>(2, 3, 4), Vec<3>(1, 2, 3), 1, {false, false, false});
    NodeField<3> nodes;
    nodes.resize(grid.n_nodes());
    Particles<3> ps;
    ps.add(Vec<3>(0.5, 0.5, 0.5), Vec<3>(1, 2, 3), 1.0, 1.0, Vec<3>(0.5, 0.5, 0.5), 0, 0);
    SnapshotWriter<3> writer(dir.path() / "d3", "solid");
    writer.write(ps, 0.0, 0, &grid, &nodes);
    EXPECT_TRUE(fs::exists(dir.path() / "d3" / "solid.xdmf"));
    EXPECT_TRUE(fs::exists(dir.path() / "d3" / "snapshots" / "solid-000000.h5"));
    const std::string xdmf = read_all(writer.grid_xdmf_path());
    EXPECT_NE(xdmf.find("TopologyType=\"3DCoRectMesh\" Dimensions=\"5 4 3\""), std::string::npos) << xdmf;
    EXPECT_NE(xdmf.find(">0 0 0</DataItem>"), std::string::npos) << xdmf;  // no ghost layers
    EXPECT_NE(xdmf.find(">3 2 1</DataItem>"), std::string::npos) << xdmf;
  }
}

TEST(Snapshot, RestartContinuesListing) {
  TempDir dir;
  Particles<2> ps;
  ps.add(Vec<2>(0.5, 0.5), Vec<2>(0, 0), 1.0, 1.0, Vec<2>(0.5, 0.5), 0, 0);
  std::vector<std::pair<double, std::string>> saved;
  int saved_index = 0;
  {
    SnapshotWriter<2> first(dir.path());
    first.write(ps, 0.0, 0);
    first.write(ps, 0.1, 1);
    saved = first.entries();  // "checkpoint" here
    saved_index = first.next_index();
    first.write(ps, 0.2, 2);  // written after the checkpoint, then the run dies
  }
  SnapshotWriter<2> second(dir.path());
  second.set_entries(saved);
  second.set_next_index(saved_index);
  ps.add(Vec<2>(0.6, 0.6), Vec<2>(0, 0), 1.0, 1.0, Vec<2>(0.5, 0.5), 0, 0);
  second.write(ps, 0.2, 2);
  ASSERT_EQ(second.entries().size(), 3u);
  EXPECT_EQ(second.entries()[2].second, "particles-000002.h5");
  const std::string xdmf = read_all(second.particles_xdmf_path());
  for (const char* f : {"particles-000000.h5", "particles-000001.h5", "particles-000002.h5"}) {
    EXPECT_NE(xdmf.find(std::string("snapshots/") + f + ":/particles/mass"), std::string::npos) << f;
  }
  // Old files keep their particle counts, the rewritten one has the new count.
  EXPECT_NE(xdmf.find("NumberOfElements=\"1\""), std::string::npos);
  EXPECT_NE(xdmf.find("NumberOfElements=\"2\""), std::string::npos);
  EXPECT_EQ(xdmf.find("particles-000003"), std::string::npos);
  EXPECT_EQ(list_dir(dir.path() / "snapshots").size(), 3u);  // no temp files left
}

TEST(Snapshot, MissingListedFileIsLeftOut) {
  TempDir dir;
  Particles<2> ps;
  ps.add(Vec<2>(0.5, 0.5), Vec<2>(0, 0), 1.0, 1.0, Vec<2>(0.5, 0.5), 0, 0);
  SnapshotWriter<2> writer(dir.path());
  writer.set_entries({{0.0, "particles-000000.h5"}});  // never written
  writer.set_next_index(1);
  writer.write(ps, 0.1, 1);
  const std::string xdmf = read_all(writer.particles_xdmf_path());
  EXPECT_EQ(xdmf.find("particles-000000.h5"), std::string::npos);
  EXPECT_NE(xdmf.find("particles-000001.h5"), std::string::npos);
  EXPECT_EQ(writer.entries().size(), 2u);
}

// ---------------------------------------------------------------------------------------------
// Self-describing files (issue 15)

TEST(Sha256, KnownDigests) {
  // FIPS 180-4 examples (NIST CSRC) and the empty string.
  EXPECT_EQ(sha256_hex(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha256_hex("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha256_hex("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha256_hex(std::string(1000000, 'a')),
            "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Units, SymbolsFollowTheDeclaredSystem) {
  EXPECT_EQ(unit_symbol("SI", Quantity::stress), "Pa");
  EXPECT_EQ(unit_symbol("mm_t_s", Quantity::stress), "MPa");
  EXPECT_EQ(unit_symbol("mm_t_s", Quantity::energy), "mJ");
  EXPECT_EQ(unit_symbol("mm_kg_ms", Quantity::stress), "GPa");
  EXPECT_EQ(unit_symbol("mm_kg_ms", Quantity::velocity), "m/s");
  EXPECT_EQ(unit_symbol("unspecified", Quantity::force), "mass*length/time^2");
  EXPECT_THROW((void)unit_symbol("furlong", Quantity::length), std::invalid_argument);
  for (const auto& name : unit_system_names()) EXPECT_EQ(unit_symbol(name, Quantity::dimensionless), "1");
}

namespace {

OutputMetadata example_metadata() {
  OutputMetadata m;
  m.title = "probe";
  m.units = "mm_t_s";
  m.material_names = {"steel", "rubber"};
  m.body_names = {"left", "right", "ball"};
  m.input_toml = "[simulation]\ndimension = 2\n";
  return m;
}

std::string dataset_attribute(hid_t loc, const std::string& dataset, const std::string& name) {
  h5::Handle d(H5Dopen2(loc, dataset.c_str(), H5P_DEFAULT), H5Dclose);
  EXPECT_GE(d.get(), 0) << dataset;
  return h5::read_string_attribute(d.get(), name);
}

}  // namespace

TEST(Snapshot, FilesDescribeThemselves) {
  TempDir dir;
  Particles<2> ps;
  ps.add(Vec<2>(0.1, 0.2), Vec<2>(1.0, -2.0), 3.0, 0.5, Vec<2>(0.1, 0.1), 1, 2);
  ps.add(Vec<2>(0.3, 0.4), Vec<2>(0.0, 0.0), 5.0, 0.25, Vec<2>(0.1, 0.1), 0, 1);
  ps.deformation_gradient[1] << 1.0, 0.5, 0.0, 0.25, 2.0, 0.0, 0.0, 0.0, 1.0;
  const OutputMetadata meta = example_metadata();
  SnapshotWriter<2> writer(dir.path(), "particles", meta);
  writer.write(ps, 0.25, 7);

  h5::Handle f = h5::open_file(writer.snapshot_path(0));
  const hid_t root = f.get();
  EXPECT_EQ(h5::read_string_attribute(root, "format"), "cairn-snapshot");
  EXPECT_EQ(h5::read_int64_attribute(root, "format_version"), snapshot_format_version);
  EXPECT_EQ(h5::read_string_attribute(root, "cairn_version"), CAIRN_VERSION);
  EXPECT_EQ(h5::read_string_attribute(root, "title"), "probe");
  EXPECT_EQ(h5::read_string_attribute(root, "units"), "mm_t_s");
  EXPECT_EQ(h5::read_string_attribute(root, "unit_length"), "mm");
  EXPECT_EQ(h5::read_string_attribute(root, "unit_mass"), "t");
  EXPECT_EQ(h5::read_string_attribute(root, "time_units"), "s");
  EXPECT_EQ(h5::read_string_attribute(root, "input_sha256"), sha256_hex(meta.input_toml));
  EXPECT_EQ(h5::read_text(root, "input"), meta.input_toml);
  EXPECT_EQ(h5::read_text_list(root, "material_names"), meta.material_names);
  EXPECT_EQ(h5::read_text_list(root, "body_names"), meta.body_names);

  h5::Handle g = h5::open_group(root, "particles");
  EXPECT_EQ(dataset_attribute(g.get(), "stress", "units"), "MPa");
  EXPECT_EQ(dataset_attribute(g.get(), "stress", "components"), "xx yy zz xy yz xz");
  EXPECT_EQ(dataset_attribute(g.get(), "velocity", "units"), "mm/s");
  EXPECT_EQ(dataset_attribute(g.get(), "position", "components"), "x y z");
  EXPECT_EQ(dataset_attribute(g.get(), "deformation_gradient", "components"), "xx xy xz yx yy yz zx zy zz");
  EXPECT_EQ(dataset_attribute(g.get(), "mass", "units"), "t");
  EXPECT_FALSE(dataset_attribute(g.get(), "von_mises", "description").empty());
  EXPECT_EQ(h5::read_ints(g.get(), "connectivity", 2), (std::vector<std::int32_t>{0, 1}));
  // The row views of F read like ordinary arrays.
  EXPECT_EQ(h5::read_doubles(g.get(), "deformation_gradient_x", {2, 3}),
            (std::vector<double>{1, 0, 0, 1.0, 0.5, 0.0}));
  EXPECT_EQ(h5::read_doubles(g.get(), "deformation_gradient_y", {2, 3}),
            (std::vector<double>{0, 1, 0, 0.25, 2.0, 0.0}));
  EXPECT_EQ(dataset_attribute(g.get(), "deformation_gradient_y", "components"), "yx yy yz");

  // The XDMF gives every reader its cells, the stress as a symmetric tensor and the rows of F.
  const std::string xdmf = read_all(writer.particles_xdmf_path());
  EXPECT_NE(xdmf.find("NodesPerElement=\"1\">\n          <DataItem Dimensions=\"2\" NumberType=\"Int\" "
                      "Precision=\"4\" Format=\"HDF\">snapshots/particles-000000.h5:/particles/connectivity"),
            std::string::npos) << xdmf;
  EXPECT_NE(xdmf.find("<Attribute Name=\"stress\" AttributeType=\"Tensor6\""), std::string::npos);
  EXPECT_NE(xdmf.find("<Attribute Name=\"deformation_gradient_z\" AttributeType=\"Vector\""), std::string::npos);
}

TEST(Snapshot, CompressionKeyChunksLargeDatasets) {
  TempDir dir;
  Particles<3> ps;
  const std::size_t n = 5000;
  for (std::size_t p = 0; p < n; ++p)
    ps.add(Vec<3>(0.001 * p, 0.5, 0.5), Vec<3>(1.0, 0.0, 0.0), 1.0, 1.0, Vec<3>(0.1, 0.1, 0.1), 0, 0);
  auto filters = [](const fs::path& file, const std::string& dataset) {
    h5::Handle f = h5::open_file(file);
    h5::Handle d(H5Dopen2(f.get(), dataset.c_str(), H5P_DEFAULT), H5Dclose);
    h5::Handle plist(H5Dget_create_plist(d.get()), H5Pclose);
    return std::make_pair(H5Pget_layout(plist.get()), H5Pget_nfilters(plist.get()));
  };
  OutputMetadata meta;
  SnapshotWriter<3> plain(dir.path() / "plain", "particles", meta);
  plain.write(ps, 0.0, 0);
  EXPECT_EQ(filters(plain.snapshot_path(0), "/particles/position"), std::make_pair(H5D_CONTIGUOUS, 0));
  meta.compression = 6;
  SnapshotWriter<3> packed(dir.path() / "packed", "particles", meta);
  packed.write(ps, 0.0, 0);
  EXPECT_EQ(filters(packed.snapshot_path(0), "/particles/position"), std::make_pair(H5D_CHUNKED, 2));  // shuffle, gzip
  EXPECT_EQ(filters(packed.snapshot_path(0), "/particles/material"), std::make_pair(H5D_CHUNKED, 2));
  EXPECT_LT(fs::file_size(packed.snapshot_path(0)), fs::file_size(plain.snapshot_path(0)) / 4);
  h5::Handle f = h5::open_file(packed.snapshot_path(0));
  h5::Handle g = h5::open_group(f.get(), "particles");
  const auto x = h5::read_doubles(g.get(), "position", {n, 3});
  EXPECT_EQ(x[3 * 4321], 0.001 * 4321);
  EXPECT_EQ(x[3 * 4321 + 1], 0.5);
}

TEST(Snapshot, RestoreCutsTheSeriesBackAtOnce) {
  TempDir dir;
  Particles<2> ps;
  ps.add(Vec<2>(0.5, 0.5), Vec<2>(0, 0), 1.0, 1.0, Vec<2>(0.5, 0.5), 0, 0);
  Grid<2> grid(Vec<2>(0.0, 0.0), IVec<2>(2, 2), Vec<2>(1.0, 1.0), 1, {false, false});
  NodeField<2> nodes;
  nodes.resize(grid.n_nodes());
  std::vector<std::pair<double, std::string>> saved;
  {
    SnapshotWriter<2> first(dir.path());
    first.write(ps, 0.0, 0);
    first.write(ps, 0.1, 1);
    saved = first.entries();
    first.write(ps, 0.2, 2, &grid, &nodes);  // after the "checkpoint": grid data
    first.write(ps, 0.3, 3, &grid, &nodes);
  }
  std::ofstream(dir.path() / "snapshots" / "other-000005.h5") << "not ours";
  ASSERT_TRUE(fs::exists(dir.path() / "grid.xdmf"));
  SnapshotWriter<2> second(dir.path());
  second.restore(saved, 2);
  EXPECT_EQ(list_dir(dir.path() / "snapshots"),
            (std::vector<std::string>{"other-000005.h5", "particles-000000.h5", "particles-000001.h5"}));
  const std::string xdmf = read_all(second.particles_xdmf_path());
  EXPECT_NE(xdmf.find("particles-000001.h5"), std::string::npos);
  EXPECT_EQ(xdmf.find("particles-000002.h5"), std::string::npos);
  EXPECT_EQ(xdmf.find("<Time Value=\"0.2\"/>"), std::string::npos);
  EXPECT_FALSE(fs::exists(dir.path() / "grid.xdmf"));  // no listed snapshot has grid data now
  EXPECT_EQ(second.next_index(), 2);
}

TYPED_TEST(CheckpointTest, VectorsAreStoredWithThreeComponents) {
  constexpr int D = TypeParam::value;
  TempDir dir;
  std::mt19937_64 rng(17);
  CheckpointData<D> data;
  data.particles = random_particles<D>(5, 2, rng);
  data.metadata = example_metadata();
  data.config_toml = "[simulation]\ndimension = " + std::to_string(D) + "\n";
  const fs::path file = dir.path() / "c.h5";
  write_checkpoint<D>(file, data);
  {
    h5::Handle f = h5::open_file(file);
    EXPECT_EQ(h5::read_int64_attribute(f.get(), "version"), checkpoint_format_version);
    EXPECT_EQ(h5::read_string_attribute(f.get(), "units"), "mm_t_s");
    EXPECT_EQ(h5::read_string_attribute(f.get(), "cairn_version"), CAIRN_VERSION);
    EXPECT_EQ(h5::read_string_attribute(f.get(), "input_sha256"), sha256_hex(data.config_toml));
    EXPECT_EQ(h5::read_text_list(f.get(), "body_names"), data.metadata.body_names);
    h5::Handle g = h5::open_group(f.get(), "particles");
    for (const char* name : {"position", "reference_position", "velocity", "size0"}) {
      EXPECT_EQ(h5::dataset_shape(g.get(), name), (std::vector<std::size_t>{5, 3})) << name;
      const auto v = h5::read_doubles(g.get(), name, {5, 3});
      for (std::size_t p = 0; p < 5; ++p)
        for (int a = D; a < 3; ++a) EXPECT_EQ(v[3 * p + a], 0.0) << name;
    }
  }
  const CheckpointData<D> back = read_checkpoint<D>(file);
  for (std::size_t p = 0; p < 5; ++p) {
    EXPECT_EQ(back.particles.position[p], data.particles.position[p]);
    EXPECT_EQ(back.particles.size0[p], data.particles.size0[p]);
  }

  // A version-1 checkpoint stored the vectors as n x D (and had no checksum); it still reads.
  {
    h5::Handle f(H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT), H5Fclose);
    ASSERT_GE(f.get(), 0);
    h5::write_int64_attribute(f.get(), "version", 1);
    ASSERT_GE(H5Adelete(f.get(), "checksum"), 0);
    h5::Handle g = h5::open_group(f.get(), "particles");
    ASSERT_GE(H5Ldelete(g.get(), "velocity", H5P_DEFAULT), 0);
    std::vector<double> v;
    for (const auto& x : data.particles.velocity)
      for (int a = 0; a < D; ++a) v.push_back(x[a]);
    h5::write_doubles(g.get(), "velocity", v.data(), 5, D);
  }
  const CheckpointData<D> old = read_checkpoint<D>(file);
  for (std::size_t p = 0; p < 5; ++p) EXPECT_EQ(old.particles.velocity[p], data.particles.velocity[p]);
}

TEST(OutputSchedule, CountsAnyNumberOfDueOutputsAtOnceAsOneByOne) {
  // advance() jumps to about the count and settles the rest by due() itself: the same count as
  // one increment per interval, where that is affordable ...
  for (const double interval : {1e-4, 0.1, 1.0 / 3.0, 0.7}) {
    for (const double t : {0.0, 0.99 * interval, interval, 3.0 * interval, 10.5 * interval, 1000.0 * interval}) {
      for (const long long start : {0LL, 1LL, 2LL}) {
        Schedule jump{interval, start}, step{interval, start};
        jump.advance(t);
        while (step.due(t)) ++step.done;
        EXPECT_EQ(jump.done, step.done) << "interval " << interval << ", t " << t << ", from " << start;
      }
    }
  }
  // ... and at once where it is not: a damaged checkpoint's time 2^31 with an interval of 1e-4
  // took 2e13 increments (cairn_fuzz_checkpoint); a time beyond any count is held, not looped.
  Schedule far{1e-4, 9};
  const double t = 2147483648.0;
  far.advance(t);
  EXPECT_FALSE(far.due(t));
  EXPECT_GE(t, static_cast<double>(far.done) * far.interval * (1.0 - 1e-12));  // the last one was due
  Schedule beyond{1e-4, 0};
  beyond.advance(1e300);
  EXPECT_GT(beyond.done, 1'000'000'000'000'000'000LL);
  Schedule never{0.0, 0};
  never.advance(1e300);
  EXPECT_EQ(never.done, 0);
}
