// Restart files: the complete state of a run, stored bit-exactly in HDF5.
//
// A checkpoint holds the resolved input (TOML text), the run-loop state, the history rows and
// snapshot listing written so far, and every particle array. Reading it back and continuing
// gives results identical to a run that was never interrupted. Files are written atomically.
//
// File layout (format "cairn-checkpoint", version 2; version 1 files are still read):
//   root attributes: format, version, engine (the engine that wrote it: mpm or wls; absent
//     before the engines had names, read as mpm), dimension, time, step, previous_dt, snapshot_next_index,
//     checksum (io/checksum.hpp: over everything else; a mismatch is refused on reading),
//     and the metadata of snapshots (cairn_version, title, units, unit_*, input_sha256 of
//     /config_toml); /material_names, /body_names (string lists)
//   /config_toml                         scalar string
//   /scalars/names, /scalars/values      run-loop scalars (string list, doubles)
//   /history/columns, /history/rows      string list, rows x columns doubles
//   /snapshots/times, /snapshots/files   snapshot listing (doubles, string list)
//   /contact/in_contact                  int64, the field pairs held in contact at nodes (only
//                                        with [contact] release = "separation"; each rank its
//                                        own, a pair may appear twice; absent: none)
//   /particles (attribute n_state_per_particle): position, reference_position, velocity, size0
//     (n x 3, zero beyond D, as in snapshots; version 1: n x D), mass, volume0, temperature (n,
//     only for thermal runs), deformation_gradient, kirchhoff_stress and, for APIC runs only,
//     affine_velocity (n x 9, row-major), material, body (int32, n), id (int64, n: the
//     particle's number; a run on several MPI ranks stores its particles rank after rank), state
//     (n * n_state_per_particle); version 1 files may also hold velocity_gradient (not read)
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "cairn/io/metadata.hpp"
#include "cairn/parallel/comm.hpp"
#include "cairn/particles/particles.hpp"

namespace cairn {

/// Everything a run needs to continue exactly where it stopped.
template <int D>
struct CheckpointData {
  std::string engine = "mpm";  ///< the engine that wrote it (run/engine.hpp)
  bool engine_named = true;     ///< false: a file written before engines had names (engine read as mpm)
  std::string config_toml;  ///< the resolved input, as TOML text
  double time = 0;
  long long step = 0;
  double previous_dt = 0;
  std::map<std::string, double> scalars;  ///< run-loop state: external_work, next output times, ...
  std::vector<std::string> history_columns;
  std::vector<std::vector<double>> history_rows;
  std::vector<std::pair<double, std::string>> snapshot_entries;
  int snapshot_next_index = 0;
  /// [contact] release = "separation": the record of field pairs in contact (Contact::record).
  std::vector<std::int64_t> contact_record;
  Particles<D> particles;
  OutputMetadata metadata;  ///< written as attributes (units, names, version); not read back
};

/// Current checkpoint format version written and accepted by this build.
inline constexpr int checkpoint_format_version = 2;

/// Write `data` to `path` atomically. Throws std::invalid_argument if the particle arrays have
/// inconsistent lengths or the history rows differ in length, std::runtime_error on I/O errors.
template <int D>
void write_checkpoint(const std::filesystem::path& path, const CheckpointData<D>& data);
/// The same with the particles taken from `particles` (data.particles is not read), so that a
/// running simulation is checkpointed without copying its particle arrays.
template <int D>
void write_checkpoint(const std::filesystem::path& path, const CheckpointData<D>& data,
                      const Particles<D>& particles);

/// The same written collectively by the ranks of `comm`, each passing its own particles (stored
/// rank after rank with their ids; parallel HDF5, docs/parallel.md).
template <int D>
void write_checkpoint(const std::filesystem::path& path, const CheckpointData<D>& data,
                      const Particles<D>& particles, const Comm& comm);
/// Read a checkpoint written by write_checkpoint<D>. Throws InputError (exit 2) naming the file
/// and the attribute or dataset when the file is missing, not HDF5, not a Cairn checkpoint, of
/// another format version or dimension, damaged (its checksum), or holds what this format does
/// not: a missing dataset, one of another shape or type, a particle dataset of another length
/// than /particles/mass, shapes larger than the file (docs/robustness.md, "Files from outside").
/// The values are read as they are; check_checkpoint_values() says whether a run wrote them.
template <int D>
CheckpointData<D> read_checkpoint(const std::filesystem::path& path);

/// Whether `data` (rows from `first_row` of the file `path`) holds values a run could have
/// written: finite, masses, volumes and sizes not below zero, deformation gradients with a
/// positive determinant, indices not negative, time, step and indices in range; InputError naming
/// the object otherwise. The restart calls it (run/mpm_engine.cpp); read_checkpoint does not, so
/// that any data round-trips.
template <int D>
void check_checkpoint_values(const std::filesystem::path& path, const CheckpointData<D>& data, std::size_t first_row);

/// The same on each rank of `comm`: everything but the particles, and an equal share of the
/// particle rows (any share: the run redistributes them; the file may come from any number of
/// ranks). Rank 0 alone verifies the checksum.
template <int D>
CheckpointData<D> read_checkpoint(const std::filesystem::path& path, const Comm& comm);
/// The simulation dimension stored in a checkpoint (checks format and version the same way).
int checkpoint_dimension(const std::filesystem::path& path);
/// Read every object of the file `path` (its content checksum) in a child process: InputError
/// when the HDF5 library crashes or hangs on it (HDF5 1.10 crashes on some damaged files, e.g. a
/// corrupt global heap under a string attribute). checkpoint_engine() calls it first, so that
/// restore_engine() reads no file that would end the run.
void check_readable_by_hdf5(const std::filesystem::path& path);
/// The engine that wrote a Cairn checkpoint of any engine (its `engine` attribute; files written
/// before engines had names: "fem" for the FEM's format, else "mpm"). Throws InputError, as
/// read_checkpoint does, for a file that is missing or not HDF5. On several ranks (`comm`) rank 0
/// alone checks the file (check_readable_by_hdf5 reads all of it) and every rank gets its answer
/// or its error (std::invalid_argument with the same message).
std::string checkpoint_engine(const std::filesystem::path& path, const Comm& comm = Comm::serial());

/// The run-loop scalar `name` stored in the checkpoint `path` (its /scalars); InputError naming
/// the file and /scalars/names when it is missing. stored_count: the same for a count (a whole
/// number 0..9e15; also an InputError otherwise).
double stored_scalar(const std::map<std::string, double>& scalars, const std::string& name,
                     const std::filesystem::path& path);
long long stored_count(const std::map<std::string, double>& scalars, const std::string& name,
                       const std::filesystem::path& path);

extern template void write_checkpoint<1>(const std::filesystem::path&, const CheckpointData<1>&);
extern template void write_checkpoint<2>(const std::filesystem::path&, const CheckpointData<2>&);
extern template void write_checkpoint<3>(const std::filesystem::path&, const CheckpointData<3>&);
extern template void write_checkpoint<1>(const std::filesystem::path&, const CheckpointData<1>&, const Particles<1>&);
extern template void write_checkpoint<2>(const std::filesystem::path&, const CheckpointData<2>&, const Particles<2>&);
extern template void write_checkpoint<3>(const std::filesystem::path&, const CheckpointData<3>&, const Particles<3>&);
extern template CheckpointData<1> read_checkpoint<1>(const std::filesystem::path&);
extern template CheckpointData<2> read_checkpoint<2>(const std::filesystem::path&);
extern template CheckpointData<3> read_checkpoint<3>(const std::filesystem::path&);

}  // namespace cairn
