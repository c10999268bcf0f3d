#include "cairn/fem/solver.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "cairn/config/errors.hpp"
#include "cairn/materials/plane_stress.hpp"
#include "cairn/util/failure.hpp"

namespace cairn::fem {
namespace {

Mat3 embed(const Eigen::Matrix2d& m, double zz) {
  Mat3 out = Mat3::Zero();
  out.topLeftCorner<2, 2>() = m;
  out(2, 2) = zz;
  return out;
}

/// Smallest altitude 2 area / longest edge of a triangle: the element length of Eq. 34.
double altitude(const Vec<2>& a, const Vec<2>& b, const Vec<2>& c) {
  const Vec<2> e0 = b - a, e1 = c - b, e2 = a - c;
  const double twice_area = std::abs(e0[0] * (c - a)[1] - e0[1] * (c - a)[0]);
  const double longest = std::sqrt(std::max({e0.squaredNorm(), e1.squaredNorm(), e2.squaredNorm()}));
  return twice_area / longest;
}

}  // namespace

Solver::Solver(const Config& config) : Solver(config, make_mesh(config.fem)) {}

Solver::Solver(const Config& config, TriangleMesh mesh) : config_(config), mesh_(std::move(mesh)) {
  check_mesh(mesh_, config_.fem.mesh_file.empty() ? "fem.shape" : "fem.mesh_file");
  setup();
}

void Solver::setup() {
  const auto& cfg = config_;
  mode_ = cfg.simulation.mode;
  thickness_ = cfg.simulation.thickness;
  const MaterialConfig* mc = nullptr;
  for (const auto& m : cfg.materials)
    if (m.name == cfg.fem.material) mc = &m;
  if (!mc) throw std::invalid_argument("fem.material '" + cfg.fem.material + "' names no [[material]]");
  material_ = make_material(*mc);
  // The FEM's energy totals and time step know nothing of a viscous stress (docs/materials.md).
  if (material_->damping_time() > 0.0)
    throw std::invalid_argument("material '" + mc->name + "': damping_time is not available in the FEM ([fem])");
  n_state_ = material_->n_state();

  const std::size_t nn = mesh_.n_nodes(), ne = mesh_.n_elements();
  const double rho0 = material_->density();
  grad0_.resize(ne);
  volume0_.resize(ne);
  mass_.assign(nn, 0.0);
  for (std::size_t e = 0; e < ne; ++e) {
    const auto& t = mesh_.triangles[e];
    const Vec<2>& X0 = mesh_.nodes[t[0]];
    Eigen::Matrix2d J;  // columns X1 - X0, X2 - X0
    J.col(0) = mesh_.nodes[t[1]] - X0;
    J.col(1) = mesh_.nodes[t[2]] - X0;
    const double area = 0.5 * J.determinant();
    // Gradients of the barycentric functions: rows of J^-1 for phi_1, phi_2; phi_0 = 1 - both.
    const Eigen::Matrix2d Jinv = J.inverse();
    grad0_[e].col(1) = Jinv.row(0).transpose();
    grad0_[e].col(2) = Jinv.row(1).transpose();
    grad0_[e].col(0) = -grad0_[e].col(1) - grad0_[e].col(2);
    volume0_[e] = area * thickness_;
    for (const auto i : t) mass_[i] += rho0 * volume0_[e] / 3.0;  // seed 001 Eq. A2
  }
  // node -> element corners, for a race-free gather of the element forces
  node_first_.assign(nn + 1, 0);
  for (const auto& t : mesh_.triangles)
    for (const auto i : t) ++node_first_[i + 1];
  for (std::size_t i = 0; i < nn; ++i) node_first_[i + 1] += node_first_[i];
  node_elem_.resize(3 * ne);
  std::vector<std::int32_t> fill(node_first_.begin(), node_first_.end() - 1);
  for (std::size_t e = 0; e < ne; ++e)
    for (int k = 0; k < 3; ++k) node_elem_[fill[mesh_.triangles[e][k]]++] = static_cast<std::int32_t>(3 * e + k);

  // initial state
  x_ = mesh_.nodes;
  v_.assign(nn, Vec<2>::Zero());
  a_.assign(nn, Vec<2>::Zero());
  b_.assign(nn, Vec<2>::Zero());
  reaction_.assign(nn, Vec<2>::Zero());
  element_force_.assign(3 * ne, Vec<2>::Zero());
  F_.assign(ne, Mat3::Identity());
  tau_.assign(ne, Mat3::Zero());
  element_state_.assign(ne * static_cast<std::size_t>(n_state_), 0.0);
  temperature_.assign(ne, material_->initial_temperature());
  for (std::size_t e = 0; e < ne && n_state_ > 0; ++e)
    material_->initialize_state(&element_state_[e * static_cast<std::size_t>(n_state_)]);

  const Constants& constants = cfg.constants;
  const auto field = [&](const std::vector<std::string>& texts, const char* key) {
    try {
      return std::make_unique<ExpressionVector<2>>(texts, constants);
    } catch (const std::invalid_argument& e) {
      throw InputError(cfg.fem.where.file, cfg.fem.where.line, key, "an expression muParser accepts", e.what());
    }
  };
  {
    auto vel = field(cfg.fem.velocity, "fem.velocity");
    for (std::size_t i = 0; i < nn; ++i) v_[i] = (*vel)(mesh_.nodes[i], mesh_.nodes[i], 0.0);
  }
  if (!cfg.fem.displacement.empty()) {
    auto u = field(cfg.fem.displacement, "fem.displacement");
    for (std::size_t i = 0; i < nn; ++i) x_[i] = mesh_.nodes[i] + (*u)(mesh_.nodes[i], mesh_.nodes[i], 0.0);
  }
  if (!cfg.fem.exact_displacement.empty()) exact_ = field(cfg.fem.exact_displacement, "fem.exact_displacement");
  if (!cfg.body_force.expression.empty()) {
    try {
      body_force_ = std::make_unique<ExpressionVector<2>>(cfg.body_force.expression, constants);
    } catch (const std::invalid_argument& e) {
      throw InputError(cfg.source_file, 0, "body_force.expression", "an expression muParser accepts", e.what());
    }
  }

  // node conditions: [boundary] faces of the mesh's bounding box, then [[velocity]] node sets
  Vec<2> lo = mesh_.nodes.front(), hi = lo;
  for (const auto& X : mesh_.nodes) {
    lo = lo.cwiseMin(X);
    hi = hi.cwiseMax(X);
  }
  const double tol = 1e-9 * (hi - lo).norm();
  const auto on_face = [&](const Vec<2>& X, int face) {
    const int axis = face / 2;
    return std::abs(X[axis] - (face % 2 == 0 ? lo[axis] : hi[axis])) <= tol;
  };
  for (int face = 0; face < 4; ++face) {
    const FaceCondition fc = cfg.boundary.face[face];
    if (fc != FaceCondition::fixed && fc != FaceCondition::symmetry) continue;
    std::vector<std::int32_t> nodes;
    for (std::size_t i = 0; i < nn; ++i)
      if (on_face(mesh_.nodes[i], face)) nodes.push_back(static_cast<std::int32_t>(i));
    for (int axis = 0; axis < 2; ++axis) {
      if (fc == FaceCondition::symmetry && axis != face / 2) continue;
      NodeCondition c;
      c.nodes = nodes;
      c.direction = axis == 0 ? Vec<2>::UnitX() : Vec<2>::UnitY();
      conditions_.push_back(std::move(c));
    }
  }
  for (const auto& vc : cfg.velocity_conditions) {
    NodeCondition c;
    c.name = vc.name;
    c.direction = Vec<2>(vc.direction[0], vc.direction[1]);
    try {
      c.velocity = std::make_shared<TimeFunction>(vc.velocity, vc.table, constants, "velocity");
    } catch (const std::invalid_argument& e) {
      throw InputError(vc.where.file, vc.where.line, "velocity." + vc.name, "a time function", e.what());
    }
    for (std::size_t i = 0; i < nn; ++i) {
      const Vec<2>& X = mesh_.nodes[i];
      bool in = true;
      if (vc.face >= 0) in = in && on_face(X, vc.face);
      if (!vc.box_min.empty())
        for (int a = 0; a < 2; ++a) in = in && X[a] >= vc.box_min[a] - tol && X[a] <= vc.box_max[a] + tol;
      if (vc.plane_axis >= 0) in = in && std::abs(X[vc.plane_axis] - vc.plane_at) <= tol;
      if (in) c.nodes.push_back(static_cast<std::int32_t>(i));
    }
    if (c.nodes.empty())
      throw InputError(vc.where.file, vc.where.line, "velocity." + vc.name,
                       "a node set with at least one mesh node (face, box and plane select reference "
                       "positions)",
                       "no node");
    conditions_.push_back(std::move(c));
  }
  apply_conditions(v_, 0.0);
  update_stresses(0.0);
  compute_accelerations();
  measure_error();
}

void Solver::measure_error() {
  if (!exact_) return;
  double err = 0.0;
  for (std::size_t i = 0; i < x_.size(); ++i) {
    const Vec<2>& X = mesh_.nodes[i];
    err = std::max(err, (x_[i] - X - (*exact_)(x_[i], X, time_)).norm());  // seed 001 Eq. 38
  }
  error_now_ = err;
  error_max_ = std::max(error_max_, err);
}

double Solver::condition_velocity(const NodeCondition& c, double t) const {
  return c.velocity ? (*c.velocity)(t) : 0.0;
}

void Solver::apply_conditions(std::vector<Vec<2>>& v, double t) const {
  for (const auto& c : conditions_) {
    const double value = condition_velocity(c, t);
    for (const auto i : c.nodes) v[i] += (value - v[i].dot(c.direction)) * c.direction;
  }
}

Vec<2> Solver::body_force(std::size_t i, double t) {
  if (!body_force_) return Vec<2>::Zero();
  return (*body_force_)(x_[i], mesh_.nodes[i], t);
}

void Solver::update_stresses(double dt) {
  const auto ne = static_cast<std::int64_t>(mesh_.n_elements());
  std::int64_t first_bad = -1;
  std::string what;
#pragma omp parallel for schedule(static)
  for (std::int64_t e = 0; e < ne; ++e) {
    const auto& t = mesh_.triangles[static_cast<std::size_t>(e)];
    const auto& G = grad0_[static_cast<std::size_t>(e)];
    // F = sum_i x_i (x) grad_X phi_i; the same as Eq. A4, (I - sum_i u_i (x) grad_x phi_i)^-1.
    Eigen::Matrix2d F2 = Eigen::Matrix2d::Zero(), Lv = Eigen::Matrix2d::Zero();
    for (int k = 0; k < 3; ++k) F2 += x_[t[k]] * G.col(k).transpose();
    const double J2 = F2.determinant();
    Mat3& F = F_[static_cast<std::size_t>(e)];
    const Mat3 F_old = F;
    F = embed(F2, mode_ == Mode::plane_stress ? F(2, 2) : 1.0);
    Mat3 tau = Mat3::Zero();
    const char* bad = nullptr;
    if (!(J2 > 0.0) || !std::isfinite(J2)) {
      bad = "det F";
    } else {
      // velocity gradient L = sum_i v_i (x) grad_x phi_i, grad_x phi = F^-T grad_X phi
      const Eigen::Matrix2d Finv_T = F2.inverse().transpose();
      for (int k = 0; k < 3; ++k) Lv += v_[t[k]] * (Finv_T * G.col(k)).transpose();
      const Mat3 L = embed(Lv, 0.0);
      double* state = n_state_ ? &element_state_[static_cast<std::size_t>(e) * static_cast<std::size_t>(n_state_)] : nullptr;
      MaterialPoint point{F, L, state, dt};
      const Mat3 dF = F * F_old.inverse();
      point.dF = &dF;
      const SymMat3 tau_old = tau_[static_cast<std::size_t>(e)];
      point.tau_old = &tau_old;
      point.cell_size = altitude(x_[t[0]], x_[t[1]], x_[t[2]]);
      point.temperature = &temperature_[static_cast<std::size_t>(e)];
      tau = mode_ == Mode::plane_stress ? plane_stress_update(*material_, F, point) : material_->update(point);
      if (!tau.allFinite()) bad = "stress";
    }
    tau_[static_cast<std::size_t>(e)] = tau;
    if (bad) {
#pragma omp critical(cairn_fem_failure)
      if (first_bad < 0 || e < first_bad) {
        first_bad = e;
        what = bad;
      }
      continue;
    }
    // seed 001 Eq. A3 over the element's current volume v_e: f_i = -v_e sigma grad_x phi_i
    // = -V_e tau F^-T grad_X phi_i (tau = J sigma, v_e = J V_e; plane stress included).
    const Eigen::Matrix2d P = tau.topLeftCorner<2, 2>() * F2.inverse().transpose();
    for (int k = 0; k < 3; ++k)
      element_force_[3 * static_cast<std::size_t>(e) + k] = -volume0_[static_cast<std::size_t>(e)] * (P * G.col(k));
  }
  if (first_bad >= 0) {
    const auto e = static_cast<std::size_t>(first_bad);
    const std::string value = what == "det F"
                                  ? fmt::format("det F = {:.6g}", F_[e].topLeftCorner<2, 2>().determinant())
                                  : what + " is not finite";
    throw SimulationFailure(first_bad, what,
                            fmt::format("element {} (mesh element {}): {}", first_bad,
                                        e < mesh_.element_tags.size() ? mesh_.element_tags[e] : e + 1, value));
  }
}

void Solver::compute_accelerations() {
  const auto nn = static_cast<std::int64_t>(mesh_.n_nodes());
  const bool constant_b = !body_force_ || body_force_->is_constant();
  if (body_force_) {
    // muParser is not thread safe: evaluate serially (once when constant).
    if (constant_b) {
      const Vec<2> b = body_force(0, time_);
      std::fill(b_.begin(), b_.end(), b);
    } else {
      for (std::int64_t i = 0; i < nn; ++i) b_[static_cast<std::size_t>(i)] = body_force(static_cast<std::size_t>(i), time_);
    }
  }
#pragma omp parallel for schedule(static)
  for (std::int64_t i = 0; i < nn; ++i) {
    Vec<2> f = Vec<2>::Zero();
    for (std::int32_t s = node_first_[i]; s < node_first_[i + 1]; ++s) f += element_force_[node_elem_[s]];
    const auto n = static_cast<std::size_t>(i);
    a_[n] = f / mass_[n] + b_[n];  // seed 001 Eq. A1
    reaction_[n].setZero();
  }
  // conditions: the constrained component of a is the prescribed velocity's rate
  constexpr double dt_fd = 1e-7;
  for (const auto& c : conditions_) {
    const double rate = c.velocity && !c.velocity->is_constant()
                            ? (condition_velocity(c, time_ + dt_fd) - condition_velocity(c, std::max(0.0, time_ - dt_fd))) /
                                  (time_ + dt_fd - std::max(0.0, time_ - dt_fd))
                            : 0.0;
    for (const auto i : c.nodes) {
      const double change = rate - a_[i].dot(c.direction);
      a_[i] += change * c.direction;
      reaction_[i] += mass_[i] * change * c.direction;
    }
  }
}

void Solver::step(double dt) {
  // Eq. A5-A6 as velocity Verlet: v(n+1/2) = v(n) + a(n) dt/2, x(n+1) = x(n) + v(n+1/2) dt,
  // a(n+1) from x(n+1), v(n+1) = v(n+1/2) + a(n+1) dt/2. For a constant dt this is the
  // central difference v(n+1/2) = v(n-1/2) + a(n) dt with the half first step of seed 001
  // Sec. 4 (end), and it gives v and the kinetic energy at whole steps.
  const auto nn = mesh_.n_nodes();
  std::vector<Vec<2>> x_old = x_;
  std::vector<Vec<2>> load_old(nn);
  for (std::size_t i = 0; i < nn; ++i) {
    load_old[i] = mass_[i] * b_[i] + reaction_[i];
    v_[i] += 0.5 * dt * a_[i];
  }
  apply_conditions(v_, time_ + 0.5 * dt);
  for (std::size_t i = 0; i < nn; ++i) x_[i] += dt * v_[i];
  time_ += dt;
  ++step_;
  update_stresses(dt);
  compute_accelerations();
  double work = 0.0;
  for (std::size_t i = 0; i < nn; ++i) {
    v_[i] += 0.5 * dt * a_[i];
    // external work of body forces and condition forces, trapezoidal in time
    work += 0.5 * (load_old[i] + mass_[i] * b_[i] + reaction_[i]).dot(x_[i] - x_old[i]);
    if (!v_[i].allFinite() || !x_[i].allFinite())
      throw SimulationFailure(static_cast<std::int64_t>(i), "velocity", fmt::format("node {}: velocity or position is not finite", i));
  }
  apply_conditions(v_, time_);
  external_work_ += work;
  measure_error();
}

double Solver::next_dt() const {
  const auto& s = config_.simulation;
  double dt = s.fixed_dt;
  if (dt <= 0.0) {
    double h = std::numeric_limits<double>::infinity(), c = 0.0, vmax = 0.0;
    const auto ne = static_cast<std::int64_t>(mesh_.n_elements()), nn = static_cast<std::int64_t>(v_.size());
#pragma omp parallel for reduction(min : h) reduction(max : c)
    for (std::int64_t e = 0; e < ne; ++e) {
      const auto& t = mesh_.triangles[static_cast<std::size_t>(e)];
      h = std::min(h, altitude(x_[t[0]], x_[t[1]], x_[t[2]]));
      c = std::max(c, material_->wave_speed(F_[static_cast<std::size_t>(e)]));
    }
#pragma omp parallel for reduction(max : vmax)
    for (std::int64_t i = 0; i < nn; ++i) vmax = std::max(vmax, v_[static_cast<std::size_t>(i)].norm());
    dt = s.cfl * h / (c + vmax);  // seed 001 Eq. 34
  }
  const double remaining = s.end_time - time_;
  if (remaining > 0.0 && dt > remaining) dt = remaining;
  return dt;
}

FemTotals Solver::totals() const {
  FemTotals t;
  for (std::size_t i = 0; i < mesh_.n_nodes(); ++i) {
    t.kinetic_energy += 0.5 * mass_[i] * v_[i].squaredNorm();
    t.momentum.head<2>() += mass_[i] * v_[i];
    t.mass += mass_[i];
  }
  t.max_pressure = -std::numeric_limits<double>::infinity();
  for (std::size_t e = 0; e < mesh_.n_elements(); ++e) {
    const double* state = n_state_ ? &element_state_[e * static_cast<std::size_t>(n_state_)] : nullptr;
    t.strain_energy += volume0_[e] * material_->internal_energy_density(F_[e], state);
    t.max_pressure = std::max(t.max_pressure, -tau_[e].trace() / (3.0 * F_[e].determinant()));
  }
  return t;
}

std::vector<Vec<2>> Solver::reactions() const {
  std::vector<Vec<2>> out;
  for (const auto& c : conditions_) {
    if (c.name.empty()) continue;
    Vec<2> r = Vec<2>::Zero();
    for (const auto i : c.nodes) r += reaction_[i].dot(c.direction) * c.direction;
    out.push_back(r);
  }
  return out;
}

Solver::State Solver::state() const {
  return {time_, external_work_, error_now_, error_max_, step_, x_, v_, a_, b_, reaction_, F_, tau_, element_state_, temperature_};
}

void Solver::restore(const State& s) {
  if (s.x.size() != x_.size() || s.v.size() != v_.size() || s.a.size() != a_.size() || s.b.size() != b_.size() ||
      s.reaction.size() != reaction_.size() || s.F.size() != F_.size() ||
      s.tau.size() != tau_.size() || s.element_state.size() != element_state_.size() ||
      s.temperature.size() != temperature_.size())
    throw std::invalid_argument("FEM checkpoint does not match the mesh of the input");
  time_ = s.time;
  external_work_ = s.external_work;
  error_now_ = s.error_now;
  error_max_ = s.error_max;
  step_ = s.step;
  x_ = s.x;
  v_ = s.v;
  F_ = s.F;
  tau_ = s.tau;
  element_state_ = s.element_state;
  temperature_ = s.temperature;
  a_ = s.a;
  b_ = s.b;
  reaction_ = s.reaction;
}

}  // namespace cairn::fem
