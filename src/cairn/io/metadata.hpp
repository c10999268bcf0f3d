// What makes Cairn's HDF5 files self-describing: the Cairn version, the declared unit system,
// the resolved input and its SHA-256, material and body names (docs/output.md).
#pragma once

#include <string>
#include <vector>

#include "cairn/config/config.hpp"
#include "cairn/config/units.hpp"

namespace cairn {

/// File-level description shared by snapshots and checkpoints.
struct OutputMetadata {
  std::string title;
  std::string units = "unspecified";           ///< a name of unit_system_names()
  std::vector<std::string> material_names;     ///< index = the `material` array's value
  std::vector<std::string> body_names;         ///< index = the `body` array's value
  std::string input_toml;                      ///< the resolved input ("" = unknown)
  int compression = 0;                         ///< gzip level of large datasets, 0 = off
  /// A material state variable the snapshots carry (Material::state_variables), one array per
  /// name over every particle: `index[m]` is its place in the state of material m's particles,
  /// -1 where material m has no such variable (those particles show NaN).
  struct StateOutput {
    std::string name, unit, description;
    std::vector<int> index;
  };
  std::vector<StateOutput> state_variables;
  /// Unit symbol of `q` in this file's system.
  [[nodiscard]] std::string unit(Quantity q) const { return unit_symbol(units, q); }
};

/// The metadata of a validated input.
[[nodiscard]] OutputMetadata output_metadata(const Config& config);

}  // namespace cairn
