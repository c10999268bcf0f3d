// FEM output: HDF5 snapshots of nodes and triangles with an XDMF index ParaView opens
// (<dir>/fem.xdmf), and HDF5 checkpoints for `cairn restart` (docs/fem.md, Outputs).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cairn/fem/solver.hpp"

namespace cairn::fem {

class SnapshotWriter {
 public:
  /// Snapshots go to `directory`/snapshots/<stem>-NNNN.h5, the index to `directory`/<stem>.xdmf.
  explicit SnapshotWriter(std::filesystem::path directory, std::string stem = "fem");
  void write(const Solver& solver);
  /// (time, file name) of every snapshot written, for checkpoints.
  [[nodiscard]] const std::vector<std::pair<double, std::string>>& entries() const { return entries_; }
  void set_entries(std::vector<std::pair<double, std::string>> entries) { entries_ = std::move(entries); }
  [[nodiscard]] std::filesystem::path xdmf_path() const { return directory_ / (stem_ + ".xdmf"); }

 private:
  void write_xdmf() const;
  std::filesystem::path directory_;
  std::string stem_;
  std::vector<std::pair<double, std::string>> entries_;
  std::size_t n_nodes_ = 0, n_elements_ = 0;
};

/// What a checkpoint holds besides the solver state.
struct Checkpoint {
  std::string config_toml;
  Solver::State state;
  std::map<std::string, double> scalars;  ///< run-loop counters
  std::vector<std::string> history_columns;
  std::vector<std::vector<double>> history_rows;
  std::vector<std::pair<double, std::string>> snapshots;
};

inline constexpr const char* checkpoint_format = "cairn-fem-checkpoint";
void write_checkpoint(const std::filesystem::path& path, const Checkpoint& data);
/// Throws std::runtime_error for a file that is not an FEM checkpoint or is damaged.
Checkpoint read_checkpoint(const std::filesystem::path& path);
/// True when `path` is an HDF5 file whose format attribute says FEM checkpoint.
bool is_checkpoint(const std::filesystem::path& path);

}  // namespace cairn::fem
