// NumPy views of an engine's particle arrays, and its grid fields (python/src/arrays.cpp).
#pragma once

#include <string>
#include <vector>

#include "bindings.hpp"
#include "cairn/run/engine.hpp"

namespace cairn::python {

/// The particle array `name` of the engine's state as a NumPy array over the engine's own memory
/// (no copy; `base` keeps the engine alive while the array lives). Read-only unless `writable`,
/// which only velocity and temperature allow (docs/python.md says what the engine assumes).
py::object particle_array(EngineState state, py::object base, const std::string& name, bool writable);
/// The names particle_array accepts for this state (arrays not stored in this run left out).
std::vector<std::string> particle_fields(EngineState state);
/// The node fields after the last step (summed over the material fields), as copies.
py::dict grid_fields(EngineState state);
/// The [[material]] names, in the order of the `material` array's indices.
std::vector<std::string> material_names(EngineState state);

}  // namespace cairn::python
