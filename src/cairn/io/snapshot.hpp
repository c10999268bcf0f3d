// Particle (and optionally grid) snapshots in HDF5 with XDMF 3 index files for ParaView/VisIt.
//
// Layout under the output directory:
//   snapshots/<stem>-NNNNNN.h5   one file per write() (NNNNNN = running index, 6 digits)
//   <stem>.xdmf                  temporal collection of the particle data of all snapshots
//   grid.xdmf                    temporal collection of node data (only if grids were written;
//                                named <stem>-grid.xdmf when stem is not "particles")
// Every file is written atomically (see atomic_file.hpp).
//
// Snapshot file contents (format_version 2; n particles; space vectors always have 3 components,
// zero beyond D; every dataset carries "units" and "description" attributes, vectors and tensors
// a "components" attribute; docs/output.md lists everything):
//   root attributes: format = "cairn-snapshot", format_version, time, time_units, step, dimension,
//     cairn_version, title, units (the declared system), unit_length/mass/time/temperature,
//     input_sha256 (SHA-256 of /input); datasets /input (the resolved input TOML),
//     /material_names, /body_names
//   /particles/position, velocity, displacement (= x - X)      n x 3
//   /particles/mass, volume (= det F * volume0), pressure (= -tr(sigma)/3), von_mises,
//     temperature                                                 n
//   /particles/stress                Cauchy sigma = tau / det F, n x 6, xx yy zz xy yz xz (VTK order)
//   /particles/deformation_gradient  n x 9, row-major (F_xx, F_xy, F_xz, F_yx, ...), and its rows
//     deformation_gradient_x/_y/_z (n x 3 virtual views, no extra data) for ParaView
//   /particles/<state variable>      n: each material state variable by name and unit
//     (Material::state_variables, e.g. equivalent_plastic_strain), NaN for particles of materials
//     without it; the group attribute "state_variables" lists them
//   /particles/material, body        int32, n (indices into /material_names, /body_names)
//   /particles/id                    int64, n: the particle's number (creation order); a run on
//                                    several MPI ranks stores its particles rank after rank
//   /particles/connectivity          int32, 0..n-1 (the XDMF Polyvertex cells)
//   /grid (optional): node_mass (shape [nz,] [ny,] nx) and node_velocity (same shape x 3) over
//     the domain nodes j = 0..n_cells per axis (no ghost layers), x fastest; attributes origin
//     and spacing (x y z, padded with 0 and 1). grid.xdmf shows it as a 3D mesh (one node thick
//     in the missing directions) in the particles' coordinates.
// Large datasets are chunked and gzip-compressed when output.compression > 0 (one rank only:
// parallel HDF5 writes no compressed datasets here, a run on several ranks writes them plain).
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cairn/grid/grid.hpp"
#include "cairn/io/metadata.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/particles/particles.hpp"

namespace cairn {

/// Version of the snapshot layout above (root attribute format_version; 1 had no such attribute).
inline constexpr int snapshot_format_version = 2;

/// Writes numbered HDF5 snapshots of the particles (and optionally the grid) and keeps the XDMF
/// index files up to date. Its listing state (entries(), next_index()) can be checkpointed so a
/// restarted run continues the same series.
template <int D>
class SnapshotWriter {
 public:
  /// One listed snapshot: (time, file name relative to <directory>/snapshots).
  using Entry = std::pair<double, std::string>;

  /// Snapshots go to `directory`/snapshots, index files to `directory`. Nothing is written
  /// until the first write(). `meta` describes the run in every file (units, names, input).
  /// A `comm` of several ranks writes collectively (parallel HDF5): each rank passes its own
  /// particles (they are stored rank after rank, each with its id) and its grid window (each
  /// rank writes the nodes it owns); rank 0 writes the XDMF files (docs/parallel.md).
  explicit SnapshotWriter(std::filesystem::path directory, std::string stem = "particles",
                          OutputMetadata meta = {}, const Comm& comm = Comm::serial());

  /// Write snapshot number next_index() of `particles` at `time`/`step` and rewrite the XDMF
  /// index files. If both `grid` and `nodes` are given, node mass and velocity are written too
  /// (node_velocity is NodeField::velocity_new, the grid velocity after the last update).
  /// `contact_normals` (multimaterial runs, one per node, zero away from contact nodes) adds
  /// /grid/contact_normal. `order` lists the storage indices in the order to write them (a serial
  /// run whose particles are kept in cell-block order writes them in id order; null: storage
  /// order).
  /// Throws std::runtime_error on I/O failure, std::invalid_argument on inconsistent sizes.
  void write(const Particles<D>& particles, double time, long long step,
             const Grid<D>* grid = nullptr, const NodeField<D>* nodes = nullptr,
             const std::vector<Vec3>* contact_normals = nullptr,
             const std::vector<std::int32_t>* order = nullptr);

  /// Index the next write() uses in its file name.
  [[nodiscard]] int next_index() const { return next_index_; }
  /// Set the index of the next snapshot file (restart). Throws std::invalid_argument if < 0.
  void set_next_index(int index);

  /// The snapshots listed in the XDMF files, in order of writing.
  [[nodiscard]] std::vector<Entry> entries() const { return entries_; }
  /// Replace the listing (restart from a checkpoint). The XDMF files are rewritten at the next
  /// write(); listed files that no longer exist are then left out of the XDMF.
  void set_entries(std::vector<Entry> entries);

  /// Restart: replace the listing and the next index, delete this series' files numbered
  /// `next_index` or later (the abandoned continuation of the run) and rewrite the XDMF files
  /// now, so that they end where the restarted run stands.
  void restore(std::vector<Entry> entries, int next_index);

  /// Path of the snapshot file with the given index.
  [[nodiscard]] std::filesystem::path snapshot_path(int index) const;
  /// Path of the particle XDMF file (<directory>/<stem>.xdmf).
  [[nodiscard]] std::filesystem::path particles_xdmf_path() const;
  /// Path of the grid XDMF file (<directory>/grid.xdmf for the default stem).
  [[nodiscard]] std::filesystem::path grid_xdmf_path() const;

 private:
  /// What the XDMF needs to know about one snapshot file.
  struct FileInfo {
    bool readable = false;
    bool current = false;  ///< written in snapshot_format_version (older files: old XDMF form)
    std::size_t n_particles = 0;
    bool has_grid = false;
    bool has_contact_normal = false;
    std::vector<std::size_t> node_shape;  ///< grid node array shape, slowest axis first
    std::vector<double> origin, spacing;  ///< x y z
    std::vector<std::string> state_variables;  ///< their /particles arrays
  };

  const FileInfo& info(const std::string& file);
  void write_xdmf();

  std::filesystem::path directory_;
  std::string stem_;
  OutputMetadata meta_;
  Comm comm_;
  int next_index_ = 0;
  std::vector<Entry> entries_;
  std::map<std::string, FileInfo> info_;
};

extern template class SnapshotWriter<1>;
extern template class SnapshotWriter<2>;
extern template class SnapshotWriter<3>;

}  // namespace cairn
