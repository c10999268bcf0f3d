// Particles given one by one ([[body]] shape `points`, docs/geometry.md): a CSV or HDF5 file of
// positions and volumes (from another code, a DEM packing, a script), with optional initial
// velocities and temperatures. Each row becomes one particle of the body with that volume and
// mass = density x volume.
//
// The HDF5 file (.h5, .hdf5): double datasets `position` (n x D), `volume` (n), optional
// `velocity` (n x D), `temperature` (n) and `stress` (n x 6 in 3D: xx, yy, zz, yz, xz, xy;
// n x 3 in 2D: xx, yy, xy) at its root.
//
// The CSV file: a header row naming the columns, then one row per particle, fields separated by
// commas; blank lines and lines starting with '#' are skipped. Columns: x, y (2D, 3D), z (3D),
// volume (required; in 2D an area, multiplied by simulation.thickness), vx, vy, vz (optional,
// all or none; they replace the body's `velocity`), temperature (optional), and the initial
// Cauchy stress (optional, all or none, tension positive, in the model's stress unit): sxx, syy,
// szz, syz, sxz, sxy in 3D, sxx, syy, sxy in 2D. Other columns are an error (a misspelt name
// would otherwise be dropped).
#pragma once

#include <array>
#include <cstddef>
#include <memory>
#include <string>
#include <vector>

namespace cairn::geometry {

struct PointSet {
  std::string file;
  int dimension = 3;
  std::vector<std::array<double, 3>> position;  ///< first `dimension` entries used
  std::vector<double> volume;                   ///< > 0 each
  std::vector<std::array<double, 3>> velocity;  ///< empty = not given
  std::vector<double> temperature;              ///< empty = not given
  /// Initial Cauchy stress, Voigt order xx, yy, zz, yz, xz, xy (2D: zz, yz, xz zero); empty = not given.
  std::vector<std::array<double, 6>> stress;
  std::array<double, 3> lo{}, hi{};             ///< bounds of the positions
  double total_volume = 0.0;
  [[nodiscard]] std::size_t n() const { return position.size(); }
};

/// Read the point file `path` (HDF5 for .h5 / .hdf5, else CSV) for a model of `dimension` axes.
/// Throws std::invalid_argument naming the file, the line or dataset and what is wrong (a
/// missing or unknown column or dataset, a wrong shape, a value that is not a finite number, a
/// row with another number of fields, a volume not above zero, no particles).
std::shared_ptr<const PointSet> read_point_file(const std::string& path, int dimension);

}  // namespace cairn::geometry
