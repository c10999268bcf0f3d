// Constitutive models behind one narrow interface.
//
// A model turns a deformation gradient (and, for path-dependent laws, its state variables, the
// velocity gradient and the time step) into a Kirchhoff stress and a strain energy. Models are
// created by name from the material registry; each declares its own input keys, which the input
// validator uses for the [[material]] tables.
#pragma once

#include <cmath>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cairn/config/config.hpp"
#include "cairn/config/keys.hpp"
#include "cairn/config/units.hpp"
#include "cairn/math/sym_mat3.hpp"
#include "cairn/math/types.hpp"
#include "cairn/util/registry.hpp"

namespace cairn {

/// A state variable a model keeps per particle, as the outputs name it (snapshots, the Python
/// module): `name` is written as a snapshot array of its own, in the unit `unit` / `per` of the
/// run's unit system (e.g. energy / mass: J/kg in SI).
struct StateVariable {
  std::string name;  ///< snake_case, e.g. "equivalent_plastic_strain"
  int index = 0;     ///< position in the particle's n_state() doubles
  Quantity unit = Quantity::dimensionless;
  Quantity per = Quantity::dimensionless;
  std::string description;
};

/// What a stress update sees of one particle.
struct MaterialPoint {
  const Mat3& F;       ///< deformation gradient after this step's increment
  const Mat3& L;       ///< velocity gradient of this step (3x3; 0 unless Material::uses_increment())
  double* state;       ///< the particle's state variables (model-defined length)
  double dt;
  const Mat3* dF = nullptr;       ///< this step's increment exp(L dt), when known (see L)
  const SymMat3* tau_old = nullptr;  ///< Kirchhoff stress before this update, when known
  double cell_size = 0.0;         ///< grid cell size (artificial viscosity length)
  double* temperature = nullptr;  ///< the particle's temperature, updated by thermal models
  /// F is block diagonal [[F_xy, 0], [0, F_zz]] (2D and 1D runs; F_xy is 2x2), which a model
  /// may use to skip the products with the zero blocks.
  bool planar = false;
};

class Material {
 public:
  explicit Material(const MaterialConfig& cfg) : name_(cfg.name), density_(cfg.number("density")) {}
  virtual ~Material() = default;

  [[nodiscard]] const std::string& name() const { return name_; }
  [[nodiscard]] double density() const { return density_; }  ///< reference density rho_0
  /// Number of state variables per particle (0 for hyperelastic laws).
  [[nodiscard]] virtual int n_state() const { return 0; }

  /// Kirchhoff stress tau = J sigma for the deformation gradient F (3x3, full 3D).
  [[nodiscard]] virtual Mat3 kirchhoff(const Mat3& F) const = 0;
  /// Strain energy per unit reference volume W(F).
  [[nodiscard]] virtual double energy_density(const Mat3& F) const = 0;
  /// Stored plus dissipated internal energy per unit reference volume; path-dependent models
  /// read it from their state (e.g. rho0 U for the Mie-Grueneisen model). Defaults to W(F).
  [[nodiscard]] virtual double internal_energy_density(const Mat3& F, const double* state) const {
    (void)state;
    return energy_density(F);
  }
  /// Initial values of the state variables (n_state() of them).
  virtual void initialize_state(double* state) const { (void)state; }
  /// Initial particle temperature (0 for models without a thermal part).
  [[nodiscard]] virtual double initial_temperature() const { return 0.0; }
  /// Whether the model reads or updates the particle temperature (MaterialPoint::temperature).
  [[nodiscard]] virtual bool uses_temperature() const { return false; }
  /// Speed of the fastest wave at deformation F, used by the CFL time step.
  [[nodiscard]] virtual double wave_speed(const Mat3& F) const = 0;
  /// Whether wave_speed depends on F (if not, the time step asks once per material, not once
  /// per particle).
  [[nodiscard]] virtual bool wave_speed_varies() const { return true; }
  /// Retardation time beta (s) of a Kelvin-Voigt viscous stress beta C : D proportional to the
  /// elastic stiffness C (0: none; docs/materials.md, "Damping"). Damps every mode at
  /// zeta = beta omega / 2 and shortens the stable time step, which next_dt accounts for.
  [[nodiscard]] virtual double damping_time() const { return 0.0; }
  /// The cost of a step of one of its particles relative to one of a corotational linear_elastic
  /// material (its stress update against the rest of the step), measured by
  /// bench/material_cost.py: the particle's weight with [parallel] balance = "cost".
  [[nodiscard]] virtual double relative_cost() const { return 1.0; }
  /// Energy per unit reference volume the model has dissipated (a viscous stress's work), kept
  /// in its state; part of the history's dissipated_energy, not of strain_energy.
  [[nodiscard]] virtual double dissipated_energy_density(const double* state) const {
    (void)state;
    return 0.0;
  }

  /// Whether update()/update_stress() read MaterialPoint::L or MaterialPoint::dF. Models that
  /// do not (hyperelastic laws) get L = 0 and dF = I there, so the step need not assemble the
  /// 3x3 increments for them (docs/performance.md); a model that reads them must return true.
  [[nodiscard]] virtual bool uses_increment() const { return false; }

  /// General stress update; hyperelastic laws need only kirchhoff(). Path-dependent models
  /// override this and keep their history in point.state.
  virtual Mat3 update(const MaterialPoint& point) const { return kirchhoff(point.F); }
  /// The step's stress update (Task 5) into the particle's stored stress `tau`, which holds the
  /// stress before the update on entry (point.tau_old may point to it). The default stores
  /// update(point); models override it to write the six components directly, so that the hot
  /// loop makes one virtual call per particle and no 3x3 temporary.
  virtual void update_stress(const MaterialPoint& point, SymMat3& tau) const { tau = update(point); }

  /// The state variables worth showing (a subset of the n_state() doubles), for the outputs.
  [[nodiscard]] virtual std::vector<StateVariable> state_variables() const { return {}; }

  /// Messages the model has for the user since the last call (e.g. a warning said once per run);
  /// the run prints them between steps. Called from one thread.
  [[nodiscard]] virtual std::vector<std::string> take_notes() const { return {}; }

 private:
  std::string name_;
  double density_;
};

/// The signal speed that gives a damped material its stable time step through the CFL formula.
/// A Kelvin-Voigt stress beta C : D damps a mode of frequency omega at zeta = beta omega / 2; the
/// grid's highest, omega_max = 2c/h (lumped linear elements), at zeta = beta c / h. The step
/// (the viscous stress from the last step's velocity gradient) is stable for one mode
/// u'' + 2 zeta omega u' + omega^2 u = 0 while omega dt <= 2 (sqrt(1 + zeta^2) - zeta), the
/// standard bound for central differences with damping: the undamped limit h / c shrinks by
/// sqrt(1 + zeta^2) - zeta, i.e. the signal speed grows by sqrt(1 + zeta^2) + zeta.
inline double damped_signal_speed(double c, double beta, double h) {
  if (!(beta > 0.0)) return c;
  const double zeta = beta * c / h;
  return c * (std::sqrt(1.0 + zeta * zeta) + zeta);
}

/// Registry entry data beyond the factory: the model's own keys (besides name, model, density).
struct MaterialModelInfo {
  std::string doc;
  std::vector<KeyDecl> keys;
  /// Extra cross-key validation (e.g. "give exactly two elastic constants"); returns an error
  /// message or "" when fine.
  std::string (*check)(const MaterialConfig&) = nullptr;
};

using MaterialRegistry = Registry<Material, const MaterialConfig&>;

/// Declared keys and doc per model name (filled by the registration lines).
std::map<std::string, MaterialModelInfo>& material_model_info();

/// Create a material from a validated config (throws UnknownName for an unknown model).
std::unique_ptr<Material> make_material(const MaterialConfig& cfg);
/// The registered model names (the allowed values of [[material]].model).
std::vector<std::string> material_model_names();

/// Registration helper: `CAIRN_REGISTER_MATERIAL(NeoHookean, "neo_hookean", info)`.
struct MaterialRegistration {
  MaterialRegistration(const std::string& name, MaterialModelInfo info,
                       MaterialRegistry::Factory factory) {
    material_model_info()[name] = info;
    MaterialRegistry::instance().add(name, info.doc, std::move(factory));
  }
};

#define CAIRN_REGISTER_MATERIAL(Class, key, info)                                          \
  static const ::cairn::MaterialRegistration cairn_material_registration_##Class(          \
      key, info, [](const ::cairn::MaterialConfig& c) -> std::unique_ptr<::cairn::Material> { \
        return std::make_unique<Class>(c);                                                 \
      })

}  // namespace cairn
