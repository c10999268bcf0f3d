#include "cairn/bc/traction.hpp"

#include <algorithm>
#include <cstring>
#include <tuple>
#include <cmath>
#include <map>
#include <stdexcept>
#include <unordered_set>

#include "cairn/config/errors.hpp"
#include "cairn/parallel/particle_transfer.hpp"
#include "cairn/transfer/transfer.hpp"
#include "cairn/util/failure.hpp"

namespace cairn {

/// Lattice site of a particle: bodies are filled on a lattice of spacing l_p0 from the grid origin.
template <int D>
std::int64_t Tractions<D>::lattice_site(const Vec<D>& X, const Vec<D>& origin, const Vec<D>& spacing, int axis,
                                        int shift) {
  std::int64_t key = 0;
  for (int a = 0; a < D; ++a) {
    std::int64_t k = std::llround((X[a] - origin[a]) / spacing[a] - 0.5);
    if (a == axis) k += shift;
    key = (key << 21) | static_cast<std::int64_t>((k + 1) & ((1 << 21) - 1));
  }
  return key;
}

template <int D>
Tractions<D>::Tractions(const Config& config, const Grid<D>& grid, const Particles<D>& particles,
                        ParticleDomain domain) {
  if (config.tractions.empty()) return;
  domain_ = domain;
  // Occupied lattice sites per body.
  std::vector<std::unordered_set<std::int64_t>> occupied(config.bodies.size());
  for (std::size_t p = 0; p < particles.n(); ++p)
    if (particles.volume0[p] > 0.0)  // (a zero-volume sample point, a WLS surface particle, occupies no site)
      occupied[particles.body[p]].insert(
          lattice_site(particles.reference_position[p], grid.origin(), particles.size0[p]));
  select(config, grid, particles, occupied, Comm::serial());
}

template <int D>
Tractions<D>::Tractions(const Config& config, const Grid<D>& grid, const Particles<D>& particles,
                        ParticleDomain domain, const std::vector<std::unordered_set<std::int64_t>>& occupied,
                        const Comm& comm) {
  if (config.tractions.empty()) return;
  domain_ = domain;
  select(config, grid, particles, occupied, comm);
}

template <int D>
void Tractions<D>::select(const Config& config, const Grid<D>& grid, const Particles<D>& particles,
                          const std::vector<std::unordered_set<std::int64_t>>& occupied, const Comm& comm) {
  thickness_ = D == 3 ? 1.0 : config.simulation.thickness;
  const std::size_t n_bodies = config.bodies.size();

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
      // A particle without volume has no faces: the surface particles of WLS (seed 001 Eq. 13,
      // wls/arrangement.hpp), sample points on the surface between lattice sites.
      if (!(particles.volume0[p] > 0.0)) continue;
      const Vec<D>& X = particles.reference_position[p];
      const Vec<D>& l0 = particles.size0[p];
      for (int a = 0; a < D; ++a)
        for (int sign = -1; sign <= 1; sign += 2) {
          const int face = 2 * a + (sign > 0 ? 1 : 0);
          if (tc.side >= 0 && tc.side != face) continue;
          if (occupied[particles.body[p]].count(lattice_site(X, grid.origin(), l0, a, sign))) continue;
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
                            static_cast<std::int16_t>(sign), static_cast<std::int32_t>(k), particles.id[p], true});
          ++load.n_faces;
        }
    }
    load.n_faces = static_cast<std::size_t>(comm.sum(static_cast<std::int64_t>(load.n_faces)));
    if (load.n_faces == 0)
      throw InputError(tc.where.file, tc.where.line, "traction[" + std::to_string(k) + "]",
                       "a selection (body, side, box_min/box_max) holding at least one exposed particle face",
                       "traction '" + tc.name + "', which selects none");
    loads_.push_back(std::move(load));
  }

  if (comm.parallel()) {
    // Every rank's faces, in the serial order: by load, particle id, axis and side.
    Comm::Buffers send(static_cast<std::size_t>(comm.size()));
    for (auto& buffer : send) {
      buffer.resize(faces_.size() * sizeof(Face));
      if (!faces_.empty()) std::memcpy(buffer.data(), faces_.data(), buffer.size());
    }
    const Comm::Buffers recv = comm.all_to_all(send);
    all_faces_.clear();
    for (const auto& buffer : recv) {
      const std::size_t first = all_faces_.size();
      all_faces_.resize(first + buffer.size() / sizeof(Face));
      if (!buffer.empty()) std::memcpy(static_cast<void*>(all_faces_.data() + first), buffer.data(), buffer.size());
    }
    std::sort(all_faces_.begin(), all_faces_.end(), [](const Face& x, const Face& y) {
      return std::tie(x.load, x.id, x.axis, x.sign) < std::tie(y.load, y.id, y.axis, y.sign);
    });
    localise(particles, particles.n());
    return;
  }
  all_faces_ = faces_;
  // One proxy particle per face: the particle's extent along the face, none along the normal.
  points_.resize(faces_.size());
  for (std::size_t q = 0; q < faces_.size(); ++q) {
    const Face& f = faces_[q];
    points_.size0[q] = particles.size0[f.particle];
    points_.size0[q][f.axis] = 0.0;
    points_.deformation_gradient[q] = Mat3::Identity();
    points_.position[q] = particles.position[f.particle];
  }
  point_force_.assign(faces_.size(), Vec<D>::Zero());
}

template <int D>
void Tractions<D>::add_forces(const Grid<D>& grid, const Particles<D>& particles, const ShapeFamily<D>& shape,
                              double t, std::vector<Vec<D>>& force,
                              const std::vector<std::int32_t>* field_offset) {
  if (loads_.empty()) return;
  std::size_t q = 0;  // (for_each_face visits the faces in order)
  for_each_face(particles, t, [&](std::int32_t, const Vec<D>& centre, const Vec<D>&, const Vec<D>& face_force) {
    points_.position[q] = centre;
    points_.deformation_gradient[q] = particles.deformation_gradient[static_cast<std::size_t>(faces_[q].particle)];
    point_force_[q] = face_force;
    ++q;
  });

  try {
    shape.build(grid, points_, cache_);
  } catch (const SimulationFailure& e) {
    const auto face = static_cast<std::size_t>(e.particle());
    const std::int32_t p = face < faces_.size() ? faces_[face].particle : -1;
    throw SimulationFailure(p, "position",
                            "particle " + std::to_string(p) +
                                ": a loaded face (traction) reaches beyond the stored grid");
  }
  for (std::size_t k = 0; k < point_force_.size(); ++k) {
    const std::int32_t off = field_offset ? (*field_offset)[static_cast<std::size_t>(faces_[k].particle)] : 0;
    for_each_entry(cache_, k, [&](std::int32_t node, double S, const Vec<D>&) { force[node + off] += S * point_force_[k]; });
  }
}

template <int D>
typename Tractions<D>::FaceGeometry Tractions<D>::face_geometry(const Particles<D>& particles, std::size_t q) const {
  const Face& f = faces_[q];
  const auto p = static_cast<std::size_t>(f.particle);
  const Mat3& F = particles.deformation_gradient[p];
  // Half-edge matrix R of the particle domain: its columns are the half edges.
  Eigen::Matrix<double, D, D> R = (0.5 * particles.size0[p]).asDiagonal();
  if (domain_ == ParticleDomain::convected) {
    R = F.template topLeftCorner<D, D>() * R;
  } else if (domain_ == ParticleDomain::stretched) {
    for (int a = 0; a < D; ++a) R(a, a) *= std::abs(F(a, a));
  }
  // Face area: the face spans the half edges R e_b, b != axis; its normal points away from the
  // particle centre (along sign R e_axis).
  FaceGeometry g;
  const Vec<D> out = static_cast<double>(f.sign) * R.col(f.axis);
  g.centre = particles.position[p] + out;
  if constexpr (D == 1) {
    g.area = thickness_;
    g.normal_area = Vec<D>(out[0] > 0.0 ? thickness_ : -thickness_);
  } else if constexpr (D == 2) {
    const Vec<2> t = 2.0 * R.col(1 - f.axis);
    g.area = t.norm() * thickness_;
    g.normal_area = Vec<2>(t[1], -t[0]) * thickness_;
  } else {
    g.normal_area = (2.0 * R.col((f.axis + 1) % 3)).cross(2.0 * R.col((f.axis + 2) % 3));
    g.area = g.normal_area.norm();
  }
  if (g.normal_area.dot(out) < 0.0) g.normal_area = -g.normal_area;
  return g;
}

template <int D>
void Tractions<D>::for_each_face(
    const Particles<D>& particles, double t,
    const std::function<void(std::int32_t, const Vec<D>&, const Vec<D>&, const Vec<D>&)>& fn) {
  for (auto& load : loads_) load.total.setZero();
  double factor = 0.0;
  std::int32_t factor_of = -1;
  for (std::size_t q = 0; q < faces_.size(); ++q) {
    const Face& f = faces_[q];
    if (f.load != factor_of) {  // faces of one load are contiguous in faces_
      factor_of = f.load;
      factor = loads_[f.load].factor(t);
    }
    const FaceGeometry g = face_geometry(particles, q);
    const Vec<D> force = (factor * g.area) * loads_[f.load].traction;
    if (f.owned) loads_[f.load].total += force;
    fn(2 * D * f.load + 2 * f.axis + (f.sign > 0 ? 1 : 0), g.centre, g.normal_area, force);
  }
}

template <int D>
ExactSum Tractions<D>::power(const std::vector<Vec<D>>& v, const std::vector<std::int32_t>* field_offset) const {
  ExactSum w;
  for (std::size_t k = 0; k < point_force_.size(); ++k) {
    if (!faces_[k].owned) continue;
    const std::int32_t off = field_offset ? (*field_offset)[static_cast<std::size_t>(faces_[k].particle)] : 0;
    double face = 0.0;
    for_each_entry(cache_, k, [&](std::int32_t node, double S, const Vec<D>&) {
      face += S * point_force_[k].dot(v[node + off]);
    });
    w.add(face);
  }
  return w;
}

template <int D>
void Tractions<D>::renumber(const std::vector<std::int32_t>& old_index) {
  if (loads_.empty()) return;
  std::vector<std::int32_t> new_index(old_index.size());
  for (std::size_t k = 0; k < old_index.size(); ++k) new_index[static_cast<std::size_t>(old_index[k])] = static_cast<std::int32_t>(k);
  for (auto* faces : {&faces_, &all_faces_})
    for (Face& f : *faces)
      if (f.particle >= 0 && static_cast<std::size_t>(f.particle) < new_index.size())  // (other ranks' faces: localise)
        f.particle = new_index[static_cast<std::size_t>(f.particle)];
}

template <int D>
void Tractions<D>::localise(const Particles<D>& particles, std::size_t n_owned) {
  if (loads_.empty()) return;
  const auto ids = particles.id.begin();
  const auto owned_end = ids + static_cast<std::ptrdiff_t>(n_owned);
  const auto all_end = ids + static_cast<std::ptrdiff_t>(particles.n());
  faces_.clear();
  if (n_owned == particles.n() && !std::is_sorted(ids, all_end)) {
    // Storage in cell-block order (a node-halo rank; every particle owned): look ids up through
    // the storage sorted by id.
    std::vector<std::int32_t> by_id;
    storage_in_id_order(particles, by_id);
    auto id_at = [&](std::int32_t k) { return particles.id[static_cast<std::size_t>(k)]; };
    for (Face f : all_faces_) {
      const auto at = std::lower_bound(by_id.begin(), by_id.end(), f.id,
                                       [&](std::int32_t k, std::int64_t id) { return id_at(k) < id; });
      if (at == by_id.end() || id_at(*at) != f.id) continue;
      f.owned = true;
      f.particle = *at;
      faces_.push_back(f);
    }
  } else {
    for (Face f : all_faces_) {
      auto at = std::lower_bound(ids, owned_end, f.id);
      f.owned = at != owned_end && *at == f.id;
      if (!f.owned) {
        at = std::lower_bound(owned_end, all_end, f.id);
        if (at == all_end || *at != f.id) continue;
      }
      f.particle = static_cast<std::int32_t>(at - ids);
      faces_.push_back(f);
    }
  }
  points_.resize(faces_.size());
  for (std::size_t q = 0; q < faces_.size(); ++q) {
    points_.size0[q] = particles.size0[static_cast<std::size_t>(faces_[q].particle)];
    points_.size0[q][faces_[q].axis] = 0.0;
  }
  point_force_.assign(faces_.size(), Vec<D>::Zero());
}

template class Tractions<1>;
template class Tractions<2>;
template class Tractions<3>;

}  // namespace cairn
