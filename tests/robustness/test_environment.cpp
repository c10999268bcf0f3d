// Hostile files and a hostile environment (issue 16): edited and damaged checkpoints, the
// failure report, a full disk and symbolic links planted in the output folder.
#include <hdf5.h>

#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <utility>
#include <regex>

#include "cairn/io/atomic_file.hpp"
#include "cairn/io/checksum.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/util/failure.hpp"
#include "robustness.hpp"
#include "../support/config_builder.hpp"

namespace cairn::robustness {
namespace {

/// Run the base input to its end in dir/out; returns the checkpoint it leaves.
fs::path run_to_checkpoint(const fs::path& d) {
  const CliResult r = cairn_on("run", base_input(), d, "-q --set output.directory='\"out\"'");
  EXPECT_EQ(r.code, 0) << r.output;
  return d / "out" / "checkpoint-0000.h5";
}

/// Set particle 0's x to `x` in a checkpoint and store a matching checksum (an edited file).
void move_first_particle(const fs::path& file, double x) {
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
  ASSERT_GE(f, 0);
  const hid_t dset = H5Dopen2(f, "/particles/position", H5P_DEFAULT);
  const hid_t space = H5Dget_space(dset);
  std::vector<double> xy(static_cast<std::size_t>(H5Sget_simple_extent_npoints(space)));
  H5Dread(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, xy.data());
  xy[0] = x;
  H5Dwrite(dset, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, xy.data());
  H5Sclose(space);
  H5Dclose(dset);
  H5Adelete(f, "checksum");
  write_content_checksum(f);
  H5Fclose(f);
}

TEST(Robustness, CheckpointPositionsAreCheckedInFloatingPoint) {
  const fs::path d = case_dir("restart_position");
  const fs::path checkpoint = run_to_checkpoint(d);
  // The checkpoint is the one at the end of the run: a restart goes on to a later end time.
  const std::string later = " -q --set simulation.end_time=2e-2";
  ASSERT_EQ(cairn("restart " + checkpoint.string() + later, d).code, 0);  // unedited: fine
  for (const double x : {3e9, 1e30, -2.0}) {
    fs::copy_file(checkpoint, d / "edited.h5", fs::copy_options::overwrite_existing);
    move_first_particle(d / "edited.h5", x);
    const CliResult r = cairn("restart edited.h5" + later, d);
    EXPECT_TRUE(input_error(r, "edited.h5", "/particles/position[0]")) << x;
  }
}

/// A particle far outside the grid (or NaN) stops the run as "left the grid" before any cell
/// index is formed from its position, in every shape family's stencil builder.
TEST(Robustness, FarParticleLeavesTheGridWithoutIndexOverflow) {
  for (const std::string shape : {"linear", "bspline2", "gimp", "cpdi"}) {
    for (const double x : {3e9, 1e30, std::nan("")}) {
      Simulation<2> sim(test::box_config(2, shape));
      sim.particles().position[5][0] = x;
      try {
        sim.build_stencils();
        ADD_FAILURE() << shape << " accepted x = " << x;
      } catch (const SimulationFailure& f) {
        EXPECT_EQ(f.particle(), 5) << shape;
        EXPECT_NE(std::string(f.what()).find("left the grid"), std::string::npos) << f.what();
      }
    }
  }
  EXPECT_EQ(failure_number(-1.2345678e-7), "-1.23457e-07");
  EXPECT_EQ(failure_number(3e9), "3e+09");
}

TEST(Robustness, DamagedCheckpointIsRefusedByItsChecksum) {
  const fs::path d = case_dir("checksum");
  const fs::path checkpoint = run_to_checkpoint(d);
  // One byte inside the raw data of the particle velocities.
  haddr_t offset = HADDR_UNDEF;
  {
    const hid_t f = H5Fopen(checkpoint.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
    const hid_t dset = H5Dopen2(f, "/particles/velocity", H5P_DEFAULT);
    offset = H5Dget_offset(dset);
    H5Dclose(dset);
    H5Fclose(f);
  }
  ASSERT_NE(offset, HADDR_UNDEF);
  std::string bytes = read_text(checkpoint);
  bytes[offset + 13] = static_cast<char>(bytes[offset + 13] ^ 0x10);
  write_text(d / "damaged.h5", bytes);
  const CliResult r = cairn("restart damaged.h5 -q", d);
  EXPECT_TRUE(input_error(r, "damaged.h5", "checksum"));
  EXPECT_NE(r.output.find("changed or damaged"), std::string::npos) << r.output;
  // A damaged attribute (the time) is caught too.
  {
    fs::copy_file(checkpoint, d / "time.h5", fs::copy_options::overwrite_existing);
    const hid_t f = H5Fopen((d / "time.h5").c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    const hid_t a = H5Aopen(f, "time", H5P_DEFAULT);
    const double t = 0.5;
    H5Awrite(a, H5T_NATIVE_DOUBLE, &t);
    H5Aclose(a);
    H5Fclose(f);
  }
  EXPECT_TRUE(input_error(cairn("restart time.h5 -q", d), "time.h5", "checksum"));
}

TEST(Robustness, FailureReportNamesTheParticleWhereItIsAndWhatFailed) {
  // A neo-Hookean block squeezed so hard that F inverts within a few steps (docs/output.md).
  const fs::path d = case_dir("failure_names");
  std::string input = base_input();
  input.replace(input.find("linear_elastic"), std::string("linear_elastic").size(), "neo_hookean");
  const CliResult r = cairn_on("run", input + "velocity = [\"-1000 * (X - 0.5)\", 0.0]\n", d,
                               "-q --set simulation.dt=2e-3 --set output.directory='\"out\"'");
  ASSERT_EQ(r.code, 3) << r.output;
  EXPECT_TRUE(std::regex_search(
      r.output, std::regex("particle [0-9]+ \\(body 0, at \\([0-9.e+-]+, [0-9.e+-]+\\)\\): det F = -?[0-9.e+-]+;")))
      << r.output;
}

TEST(Robustness, FailureReportHasSignificantDigitsAndItsOwnStep) {
  const fs::path d = case_dir("failure");
  // A block squeezed at 20 m/s with a time step far above the stable one (about 1.4e-3).
  const CliResult r = cairn_on("run", base_input() + "velocity = [\"-200 * (X - 0.5)\", 0.0]\n", d,
                               "-q --set simulation.dt=2e-2 --set simulation.end_time=1.0 "
                               "--set output.directory='\"out\"'");
  ASSERT_EQ(r.code, 3) << r.output;
  EXPECT_EQ(r.output.find("0.000000"), std::string::npos) << r.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(r.output, m, std::regex("failed at step ([0-9]+) \\(t = ([0-9.e+-]+)\\)"))) << r.output;
  const long long step = std::stoll(m[1]);
  const double t = std::stod(m[2]);
  const fs::path snapshot = d / "out" / "snapshots" / "failure-000000.h5";
  ASSERT_TRUE(fs::exists(snapshot)) << r.output;
  const hid_t f = H5Fopen(snapshot.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  long long stored_step = -1;
  double stored_time = -1.0;
  const hid_t as = H5Aopen(f, "step", H5P_DEFAULT), at = H5Aopen(f, "time", H5P_DEFAULT);
  H5Aread(as, H5T_NATIVE_LLONG, &stored_step);
  H5Aread(at, H5T_NATIVE_DOUBLE, &stored_time);
  H5Aclose(as);
  H5Aclose(at);
  H5Fclose(f);
  EXPECT_EQ(stored_step, step);
  EXPECT_NEAR(stored_time, t + 2e-2, 1e-6);  // the end of the failed step, not the last good one
}

TEST(Robustness, FullDiskSaysSoAndKeepsTheHistory) {
  const fs::path d = case_dir("enospc");
  const std::string shim = std::string("LD_PRELOAD='") + CAIRN_ENOSPC_SHIM + "' ";
  // The first checkpoint (after about three steps) meets a full disk.
  CliResult r = cairn_on("run", base_input(), d,
                         "-q --set output.checkpoint_every=3e-3 --set output.directory='\"out\"'",
                         shim + "CAIRN_ENOSPC_MATCH=checkpoint-");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("no space left on device"), std::string::npos) << r.output;
  const std::string history = read_text(d / "out" / "history.csv");
  const auto rows = std::count(history.begin(), history.end(), '\n') - 1;
  EXPECT_GE(rows, 3) << history;  // t = 0 and the steps before the checkpoint
  std::vector<std::string> left;
  for (const auto& e : fs::directory_iterator(d / "out"))
    if (e.path().filename().string().find(".tmp.") != std::string::npos) left.push_back(e.path().string());
  EXPECT_TRUE(left.empty()) << left.front();
  // A text file (the history itself) on a full disk.
  r = cairn_on("run", base_input(), d, "-q --set output.directory='\"out2\"'", shim + "CAIRN_ENOSPC_MATCH=history.csv");
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_NE(r.output.find("no space left on device"), std::string::npos) << r.output;
}

// A disk quota and a failing device mid-run (issue 36): the same path as a full disk, each named.
TEST(Robustness, QuotaAndDeviceErrorsSaySoAndKeepTheHistory) {
  const fs::path d = case_dir("quota");
  const std::string shim = std::string("LD_PRELOAD='") + CAIRN_ENOSPC_SHIM + "' CAIRN_ENOSPC_MATCH=checkpoint- ";
  for (const auto& [code, says] : {std::pair{EDQUOT, "disk quota exceeded"}, std::pair{EIO, "Input/output error"}}) {
    const std::string out = "out" + std::to_string(code);
    const CliResult r = cairn_on("run", base_input(), d,
                                 "-q --set output.checkpoint_every=3e-3 --set output.directory='\"" + out + "\"'",
                                 shim + "CAIRN_ENOSPC_ERRNO=" + std::to_string(code));
    EXPECT_EQ(r.code, 1) << r.output;
    EXPECT_NE(r.output.find(says), std::string::npos) << r.output;
    const std::string history = read_text(d / out / "history.csv");
    EXPECT_GE(std::count(history.begin(), history.end(), '\n') - 1, 3) << history;
  }
}

// A read-only output folder (issue 36): exit 1 naming the file and the reason, nothing written.
// Root may write anywhere, so as root the run is made by the user nobody (runuser).
TEST(Robustness, ReadOnlyOutputFolderSaysSo) {
  const fs::path d = case_dir("readonly");
  write_text(d / "case.toml", base_input());
  fs::create_directories(d / "out");
  fs::permissions(d, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec |
                         fs::perms::others_read | fs::perms::others_exec);
  fs::permissions(d / "case.toml", fs::perms::owner_read | fs::perms::owner_write | fs::perms::group_read |
                                       fs::perms::others_read);
  fs::permissions(d / "out", fs::perms::owner_read | fs::perms::owner_exec | fs::perms::group_read |
                                 fs::perms::group_exec | fs::perms::others_read | fs::perms::others_exec);
  const std::string as = ::geteuid() == 0 ? "runuser -u nobody -- " : "";
  const std::string cmd = "cd '" + d.string() + "' && OMP_NUM_THREADS=1 " + as + "'" + CAIRN_BINARY +
                          "' run case.toml -q --set output.directory='\"out\"' > '" + (d / "log.txt").string() +
                          "' 2>&1";
  const int status = std::system(cmd.c_str());
  const std::string log = read_text(d / "log.txt");
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 1) << status << log;
  EXPECT_NE(log.find("out/history.csv"), std::string::npos) << log;
  EXPECT_NE(log.find("Permission denied"), std::string::npos) << log;
  EXPECT_TRUE(fs::is_empty(d / "out"));
  fs::permissions(d / "out", fs::perms::owner_all, fs::perm_options::add);
}

TEST(Robustness, PlantedSymlinksDoNotRedirectWrites) {
  const fs::path d = case_dir("symlink");
  const fs::path outside = d / "outside.txt";
  write_text(outside, "precious");
  // The old temporary name, and a link at the target itself.
  fs::create_directories(d / "out");
  const fs::path target = d / "out" / "history.csv";
  fs::create_symlink(outside, d / "out" / ("history.csv.tmp." + std::to_string(::getpid())));
  write_text_atomically(target, "time\n");
  EXPECT_EQ(read_text(outside), "precious");
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(target)));
  fs::remove(target);
  fs::create_symlink(outside, target);
  write_text_atomically(target, "time\n");
  EXPECT_EQ(read_text(outside), "precious");
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(target)));
  // A whole run into a folder whose checkpoint name is a planted link.
  fs::create_symlink(outside, d / "out" / "checkpoint-0000.h5");
  const CliResult r = cairn_on("run", base_input(), d, "-q --set output.directory='\"out\"'");
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(read_text(outside), "precious");
  EXPECT_TRUE(fs::is_regular_file(fs::symlink_status(d / "out" / "checkpoint-0000.h5")));
}

}  // namespace
}  // namespace cairn::robustness
