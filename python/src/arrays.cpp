// NumPy views of Particles<D> (particles/particles.hpp): the arrays are structure-of-arrays
// std::vectors of fixed-size Eigen types, so each is one strided block of doubles or integers.
#include "arrays.hpp"

#include <pybind11/numpy.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <limits>
#include <stdexcept>
#include <type_traits>
#include <utility>
#include <variant>

#include "cairn/sim/simulation.hpp"

namespace cairn::python {
namespace {

using Shape = std::vector<py::ssize_t>;

/// An array over `data` with the per-particle `tail` shape and strides (bytes), `n` particles of
/// `item` bytes each.
template <class T>
py::array view(T* data, std::size_t n, std::size_t item, const Shape& tail, const Shape& tail_strides,
               const py::object& base, bool writable) {
  Shape shape{static_cast<py::ssize_t>(n)}, strides{static_cast<py::ssize_t>(item)};
  shape.insert(shape.end(), tail.begin(), tail.end());
  strides.insert(strides.end(), tail_strides.begin(), tail_strides.end());
  static T empty{};  // numpy copies when given no pointer; an empty view needs one
  py::array a(py::dtype::of<T>(), shape, strides, n == 0 ? &empty : data, base);
  if (!writable) py::detail::array_proxy(a.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return a;
}

constexpr py::ssize_t d8 = sizeof(double);

/// Where each material keeps the state variable `name` (-1: it has none).
template <int D>
std::vector<int> state_indices(const Simulation<D>& sim, const std::string& name) {
  std::vector<int> index;
  for (const auto& m : sim.materials()) {
    index.push_back(-1);
    for (const auto& v : m->state_variables())
      if (v.name == name) index.back() = v.index;
  }
  return index;
}

/// A material state variable (Material::state_variables): a view of its column of the state
/// array when every material keeps it in the same place, else a read-only copy with NaN for the
/// particles whose material has no such variable.
template <int D>
py::object state_variable_array(Simulation<D>& sim, const py::object& base, const std::vector<int>& index) {
  auto& P = sim.particles();
  const std::size_t n = P.n(), width = static_cast<std::size_t>(P.n_state_per_particle);
  if (std::all_of(index.begin(), index.end(), [&](int k) { return k == index.front(); }))
    return view(P.state.data() + index.front(), n, width * sizeof(double), {}, {}, base, false);
  py::array_t<double> copy(static_cast<py::ssize_t>(n));
  auto out = copy.mutable_unchecked<1>();
  for (std::size_t p = 0; p < n; ++p) {
    const int k = index[static_cast<std::size_t>(P.material[p])];
    out(static_cast<py::ssize_t>(p)) = k >= 0 ? P.state[p * width + static_cast<std::size_t>(k)]
                                              : std::numeric_limits<double>::quiet_NaN();
  }
  py::detail::array_proxy(copy.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return copy;
}

template <int D>
py::object particle_array_of(Simulation<D>& sim, const py::object& base, const std::string& name, bool writable) {
  static_assert(sizeof(Vec<D>) == D * sizeof(double) && sizeof(Mat3) == 9 * sizeof(double) &&
                sizeof(SymMat3) == 6 * sizeof(double), "packed Eigen types");
  auto& P = sim.particles();
  const std::size_t n = P.n();
  if (writable && name != "velocity" && name != "temperature")
    throw std::invalid_argument("particle array '" + name + "' is read-only; the writable ones are velocity and "
                                "temperature (docs/python.md)");
  auto vectors = [&](auto& v) { return view(v.data()->data(), n, sizeof(Vec<D>), {D}, {d8}, base, writable); };
  auto scalars = [&](auto& v) { return view(v.data(), n, sizeof(v[0]), {}, {}, base, writable); };
  // Mat3 is column-major: F[p, i, j] lies at (i + 3 j) doubles.
  auto matrices = [&](auto& v) { return view(v.data()->data(), n, sizeof(Mat3), {3, 3}, {d8, 3 * d8}, base, writable); };
  if (name == "position") return vectors(P.position);
  if (name == "reference_position") return vectors(P.reference_position);
  if (name == "velocity") return vectors(P.velocity);
  if (name == "size0") return vectors(P.size0);
  if (name == "mass") return scalars(P.mass);
  if (name == "volume0") return scalars(P.volume0);
  if (name == "material") return scalars(P.material);
  if (name == "body") return scalars(P.body);
  if (name == "id") return scalars(P.id);
  if (name == "deformation_gradient") return matrices(P.deformation_gradient);
  if (name == "affine_velocity" && P.has_affine) return matrices(P.affine_velocity);
  if (name == "kirchhoff_stress")
    return view(P.kirchhoff_stress.data()->voigt().data(), n, sizeof(SymMat3), {6}, {d8}, base, writable);
  if (name == "temperature" && P.has_temperature) return scalars(P.temperature);
  if (name == "state" && P.n_state_per_particle > 0) {
    const auto k = static_cast<py::ssize_t>(P.n_state_per_particle);
    return view(P.state.data(), n, static_cast<std::size_t>(k) * sizeof(double), {k}, {d8}, base, writable);
  }
  if (const auto index = state_indices(sim, name);
      !writable && std::any_of(index.begin(), index.end(), [](int k) { return k >= 0; }))
    return state_variable_array(sim, base, index);
  throw std::invalid_argument("no particle array '" + name + "' in this run");
}

template <int D>
std::vector<std::string> particle_fields_of(const Simulation<D>& sim) {
  const auto& P = sim.particles();
  std::vector<std::string> names{"position", "reference_position", "velocity", "mass", "volume0", "size0",
                                 "deformation_gradient", "kirchhoff_stress"};
  if (P.has_affine) names.push_back("affine_velocity");
  if (P.has_temperature) names.push_back("temperature");
  names.insert(names.end(), {"material", "body", "id"});
  if (P.n_state_per_particle > 0) names.push_back("state");
  for (const auto& m : sim.materials())
    for (const auto& v : m->state_variables())
      if (std::find(names.begin(), names.end(), v.name) == names.end()) names.push_back(v.name);
  return names;
}

template <int D>
py::dict grid_fields_of(const Simulation<D>& sim) {
  const NodeField<D> nodes = sim.grid_totals();
  const Grid<D>& grid = sim.grid();
  const auto n = static_cast<std::size_t>(grid.n_nodes());
  auto vectors = [&](const std::vector<Vec<D>>& v) {
    py::array_t<double> a({static_cast<py::ssize_t>(n), static_cast<py::ssize_t>(D)});
    auto out = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < n && i < v.size(); ++i)
      for (int k = 0; k < D; ++k) out(static_cast<py::ssize_t>(i), k) = v[i][k];
    return a;
  };
  std::vector<Vec<D>> position(n);
  for (std::size_t i = 0; i < n; ++i) position[i] = grid.node_position(static_cast<std::int32_t>(i));
  py::dict d;
  d["position"] = vectors(position);
  d["mass"] = py::array_t<double>(static_cast<py::ssize_t>(nodes.mass.size()), nodes.mass.data());
  d["momentum"] = vectors(nodes.momentum);
  d["velocity"] = vectors(nodes.velocity);
  d["velocity_new"] = vectors(nodes.velocity_new);
  std::vector<int> per_axis;
  for (int a = 0; a < D; ++a) per_axis.push_back(grid.stored_nodes(a));
  d["nodes_per_axis"] = per_axis;
  return d;
}

/// fn(simulation) for an MPM/WLS state; the FEM solver and an empty state are refused.
template <class Fn>
auto with_simulation(EngineState state, Fn&& fn) {
  using Result = decltype(fn(std::declval<Simulation<2>&>()));
  return std::visit(
      [&](auto s) -> Result {
        using S = decltype(s);
        if constexpr (std::is_same_v<S, Simulation<1>*> || std::is_same_v<S, Simulation<2>*> ||
                      std::is_same_v<S, Simulation<3>*>)
          return fn(*s);
        else
          throw std::invalid_argument("particle and grid arrays exist for MPM and WLS runs only");
      },
      state);
}

}  // namespace

py::object particle_array(EngineState state, py::object base, const std::string& name, bool writable) {
  return with_simulation(state, [&](auto& sim) { return particle_array_of(sim, base, name, writable); });
}

std::vector<std::string> particle_fields(EngineState state) {
  return with_simulation(state, [](auto& sim) { return particle_fields_of(sim); });
}

py::dict grid_fields(EngineState state) {
  return with_simulation(state, [](auto& sim) { return grid_fields_of(sim); });
}

std::vector<std::string> material_names(EngineState state) {
  return with_simulation(state, [](auto& sim) {
    std::vector<std::string> names;
    for (const auto& m : sim.materials()) names.push_back(m->name());
    return names;
  });
}

}  // namespace cairn::python
