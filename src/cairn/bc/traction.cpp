#include "cairn/bc/traction.hpp"

#include <array>
#include <cmath>
#include <map>
#include <stdexcept>
#include <unordered_set>

#include "cairn/util/failure.hpp"

namespace cairn {

ParticleDomain particle_domain_of(const std::string& shape_family) {
  // The families whose particle domain deforms with F. A new family that tracks its domain adds
  // itself here (docs/boundary-conditions.md).
  static const std::map<std::string, ParticleDomain> tracked{
      {"cpdi", ParticleDomain::convected},
      {"b2cpdi", ParticleDomain::convected},
      {"cpgimp", ParticleDomain::stretched},
  };
  const auto it = tracked.find(shape_family);
  return it == tracked.end() ? ParticleDomain::undeformed : it->second;
}

namespace {

constexpr int n_gauss = 3;
const std::array<double, n_gauss> gauss_x{-0.7745966692414834, 0.0, 0.7745966692414834};
const std::array<double, n_gauss> gauss_w{5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};

constexpr int points_per_face(int D) { return D == 1 ? 1 : D == 2 ? n_gauss : n_gauss * n_gauss; }

/// Lattice site of a particle: bodies are filled on a lattice of spacing l_p0 from the grid origin.
template <int D>
std::int64_t lattice_key(const Vec<D>& X, const Vec<D>& origin, const Vec<D>& spacing, int axis = 0,
                         int shift = 0) {
  std::int64_t key = 0;
  for (int a = 0; a < D; ++a) {
    std::int64_t k = std::llround((X[a] - origin[a]) / spacing[a] - 0.5);
    if (a == axis) k += shift;
    key = (key << 21) | static_cast<std::int64_t>((k + 1) & ((1 << 21) - 1));
  }
  return key;
}

}  // namespace

template <int D>
Tractions<D>::Tractions(const Config& config, const Grid<D>& grid, const Particles<D>& particles) {
  if (config.tractions.empty()) return;
  domain_ = particle_domain_of(config.method.shape);
  thickness_ = D == 3 ? 1.0 : config.simulation.thickness;

  // Occupied lattice sites per body.
  const std::size_t n_bodies = config.bodies.size();
  std::vector<std::unordered_set<std::int64_t>> occupied(n_bodies);
  for (std::size_t p = 0; p < particles.n(); ++p)
    occupied[particles.body[p]].insert(
        lattice_key<D>(particles.reference_position[p], grid.origin(), particles.size0[p]));

  for (std::size_t k = 0; k < config.tractions.size(); ++k) {
    const TractionConfig& tc = config.tractions[k];
    const std::string what = tc.where.str() + ": traction '" + tc.name + "'";
    Load load;
    for (int a = 0; a < D; ++a) load.traction[a] = tc.traction[a];
    load.factor = TimeFunction(tc.scale, tc.table, config.constants, what);
    int body = -1;
    for (std::size_t b = 0; b < n_bodies; ++b)
      if (config.bodies[b].name == tc.body) body = static_cast<int>(b);
    if (!tc.body.empty() && body < 0) throw std::invalid_argument(what + ": no [[body]] named '" + tc.body + "'");
    const bool has_box = !tc.box_min.empty();
    for (std::size_t p = 0; p < particles.n(); ++p) {
      if (body >= 0 && particles.body[p] != body) continue;
      const Vec<D>& X = particles.reference_position[p];
      const Vec<D>& l0 = particles.size0[p];
      for (int a = 0; a < D; ++a)
        for (int sign = -1; sign <= 1; sign += 2) {
          const int face = 2 * a + (sign > 0 ? 1 : 0);
          if (tc.side >= 0 && tc.side != face) continue;
          if (occupied[particles.body[p]].count(lattice_key<D>(X, grid.origin(), l0, a, sign))) continue;
          if (has_box) {
            Vec<D> centre = X;
            centre[a] += 0.5 * sign * l0[a];
            bool in = true;
            for (int b = 0; b < D && in; ++b) {
              const double tol = 1e-9 * grid.cell_size()[b];
              in = centre[b] >= tc.box_min[b] - tol && centre[b] <= tc.box_max[b] + tol;
            }
            if (!in) continue;
          }
          faces_.push_back({static_cast<std::int32_t>(p), static_cast<std::int16_t>(a),
                            static_cast<std::int16_t>(sign), static_cast<std::int32_t>(k)});
          ++load.n_faces;
        }
    }
    if (load.n_faces == 0)
      throw std::invalid_argument(what + " selects no exposed particle face (check body, side and box)");
    loads_.push_back(std::move(load));
  }

  const std::size_t n_points = faces_.size() * points_per_face(D);
  points_.resize(n_points);
  for (std::size_t q = 0; q < n_points; ++q) {
    points_.size0[q] = Vec<D>::Zero();  // zero-size proxies: S_pi = N_i(x_q)
    points_.deformation_gradient[q] = Mat3::Identity();
    points_.position[q] = Vec<D>::Zero();
  }
  point_force_.assign(n_points, Vec<D>::Zero());
}

template <int D>
void Tractions<D>::add_forces(const Grid<D>& grid, const Particles<D>& particles, const ShapeFamily<D>& shape,
                              double t, std::vector<Vec<D>>& force) {
  if (loads_.empty()) return;
  constexpr int n_q = points_per_face(D);
  std::size_t q = 0;
  for (const Face& f : faces_) {
    const auto p = static_cast<std::size_t>(f.particle);
    // Half-edge matrix R of the particle domain: columns are the half edges (seed 000 Sec. 2.1).
    Eigen::Matrix<double, D, D> R = (0.5 * particles.size0[p]).asDiagonal();
    if (domain_ == ParticleDomain::convected) {
      R = particles.deformation_gradient[p].template topLeftCorner<D, D>() * R;
    } else if (domain_ == ParticleDomain::stretched) {
      for (int a = 0; a < D; ++a) R(a, a) *= std::abs(particles.deformation_gradient[p](a, a));
    }
    const Vec<D> centre = particles.position[p] + static_cast<double>(f.sign) * R.col(f.axis);
    // Tangent half edges and the face area.
    std::array<Vec<D>, 2> tangent{Vec<D>::Zero(), Vec<D>::Zero()};
    int n_t = 0;
    for (int b = 0; b < D; ++b)
      if (b != f.axis) tangent[n_t++] = R.col(b);
    double area = thickness_;
    if constexpr (D == 2) {
      area = 2.0 * tangent[0].norm() * thickness_;
    } else if constexpr (D == 3) {
      area = (2.0 * tangent[0]).cross(2.0 * tangent[1]).norm();
    }
    (void)n_t;
    const Vec<D>& T = loads_[f.load].traction;  // times the load's factor of this step, below
    for (int g = 0; g < n_q; ++g, ++q) {
      Vec<D> x = centre;
      double w = 1.0;
      if constexpr (D >= 2) {
        x += gauss_x[g % n_gauss] * tangent[0];
        w *= 0.5 * gauss_w[g % n_gauss];
      }
      if constexpr (D == 3) {
        x += gauss_x[g / n_gauss] * tangent[1];
        w *= 0.5 * gauss_w[g / n_gauss];
      }
      points_.position[q] = x;
      point_force_[q] = (w * area) * T;
    }
  }
  // The factor of each load at time t (faces of one load are contiguous in faces_).
  for (auto& load : loads_) load.total.setZero();
  q = 0;
  double factor = 0.0;
  std::int32_t factor_of = -1;
  for (const Face& f : faces_) {
    if (f.load != factor_of) {
      factor_of = f.load;
      factor = loads_[f.load].factor(t);
    }
    for (int g = 0; g < n_q; ++g, ++q) {
      point_force_[q] *= factor;
      loads_[f.load].total += point_force_[q];
    }
  }

  try {
    shape.build(grid, points_, cache_);
  } catch (const SimulationFailure& e) {
    const auto face = static_cast<std::size_t>(e.particle()) / n_q;
    const std::int32_t p = face < faces_.size() ? faces_[face].particle : -1;
    throw SimulationFailure(p, "position",
                            "particle " + std::to_string(p) +
                                ": a loaded face (traction) reaches beyond the stored grid");
  }
  for (std::size_t k = 0; k < point_force_.size(); ++k) {
    const std::size_t begin = k * static_cast<std::size_t>(cache_.stride);
    const std::size_t end = begin + cache_.count[k];
    for (std::size_t s = begin; s < end; ++s) force[cache_.node[s]] += cache_.weight[s] * point_force_[k];
  }
}

template <int D>
double Tractions<D>::power(const std::vector<Vec<D>>& v) const {
  double w = 0.0;
  for (std::size_t k = 0; k < point_force_.size(); ++k) {
    const std::size_t begin = k * static_cast<std::size_t>(cache_.stride);
    const std::size_t end = begin + cache_.count[k];
    for (std::size_t s = begin; s < end; ++s) w += cache_.weight[s] * point_force_[k].dot(v[cache_.node[s]]);
  }
  return w;
}

template class Tractions<1>;
template class Tractions<2>;
template class Tractions<3>;

}  // namespace cairn
