#include "cairn/contact/contact.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>
#include <stdexcept>

#include "cairn/contact/regression.hpp"
#include "cairn/parallel/particle_transfer.hpp"
#include "cairn/transfer/transfer.hpp"
#include "cairn/util/scoped_seconds.hpp"

namespace cairn {

namespace {

/// Offset from node position to x, unwrapped across periodic axes.
template <int D>
Vec<D> offset_from_node(const Grid<D>& grid, std::int32_t node, const Vec<D>& x) {
  Vec<D> d = x - grid.node_position(node);
  for (int a = 0; a < D; ++a) {
    if (!grid.periodic(a)) continue;
    const double L = grid.n_cells()[a] * grid.cell_size()[a];
    d[a] -= L * std::round(d[a] / L);
  }
  return d;
}

/// The DF table: a semi-infinite row of undeformed particles of length lp (l = h / ppc) ending
/// at e (in cells) on the -x side of the node at 0, extrapolated with the run's shape family in
/// 1D; s(e) = (sum S m x / sum S m) / h. Returned as increasing (s, e) pairs. This is the
/// d(x) curve of seed 004 Fig. 1, computed for the family and particle size in use rather than
/// fitted (the fit of ref. [13] is not in the seed).
void df_table(const MethodConfig& method, int ppc, std::vector<double>& s_out, std::vector<double>& e_out) {
  ShapeContext ctx{method, 1};
  auto shape = make_shape_family<1>(ctx);
  const int n_cells = 24;
  const double h = 1.0;
  Vec<1> origin, hh;
  origin[0] = -0.5 * n_cells * h;
  hh[0] = h;
  IVec<1> nc;
  nc[0] = n_cells;
  Grid<1> grid(origin, nc, hh, shape->ghost_layers(), {false});
  const double lp = h / ppc;
  std::int32_t node0 = -1;
  for (std::int32_t i = 0; i < grid.n_nodes(); ++i)
    if (std::abs(grid.node_position(i)[0]) < 1e-9) node0 = i;
  for (int k = -300; k <= 300; ++k) {
    const double e = k / 100.0;  // edge position in cells, -3 .. 3
    Particles<1> P;
    Vec<1> size;
    size[0] = lp;
    for (double x = e - 0.5 * lp; x > origin[0] + 3.0 * h; x -= lp) {
      Vec<1> X;
      X[0] = x;
      P.add(X, Vec<1>::Zero(), 1.0, lp, size, 0, 0);
    }
    TransferCache<1> cache;
    shape->build(grid, P, cache);
    double m = 0.0, mx = 0.0;
    for (std::size_t p = 0; p < P.n(); ++p)
      for_each_entry(cache, p, [&](std::int32_t node, double S, const Vec<1>&) {
        if (node == node0) {
          m += S;
          mx += S * P.position[p][0];
        }
      });
    if (m <= 1e-12) continue;
    const double s = mx / m;
    if (!s_out.empty() && s <= s_out.back() + 1e-12) continue;  // keep it strictly increasing
    s_out.push_back(s);
    e_out.push_back(e);
  }
}

}  // namespace

template <int D>
Contact<D>::Contact(const Config& config, const Grid<D>& grid, const Particles<D>& particles, double small_mass)
    : grid_(&grid), cfg_(config.contact), small_mass_(small_mass), n_nodes_(grid.n_nodes()) {
  (void)particles;
  by_body_ = cfg_.mode == "body";
  twice_ = cfg_.corrections == "twice";
  xpic_correction_ = cfg_.xpic_correction;
  impulse_ = cfg_.first_correction == "impulse";
  release_by_separation_ = cfg_.release == "separation";
  if (by_body_)
    for (const auto& b : config.bodies) field_names_.push_back(b.name);
  else
    for (const auto& m : config.materials) field_names_.push_back(m.name);
  const int n = n_fields();

  // Laws: the [contact] default, then each [[contact_pair]].
  const std::string where = cfg_.where.str() + ": [contact]";
  auto make = [&](const ContactLawConfig& lc, const std::string& w) {
    try {
      laws_.push_back(make_contact_law(lc, config.constants));
    } catch (const std::exception& e) {
      throw std::invalid_argument(w + ": " + e.what());
    }
  };
  make(cfg_.law, where);
  pair_law_.assign(static_cast<std::size_t>(n * n), 0);
  std::vector<std::pair<int, int>> named;
  for (const auto& pc : cfg_.pairs) {
    make(pc.law, pc.where.str() + ": [[contact_pair]]");
    const int a = static_cast<int>(std::find(field_names_.begin(), field_names_.end(), pc.first) - field_names_.begin());
    const int b = static_cast<int>(std::find(field_names_.begin(), field_names_.end(), pc.second) - field_names_.begin());
    pair_law_[static_cast<std::size_t>(a * n + b)] = pair_law_[static_cast<std::size_t>(b * n + a)] =
        static_cast<int>(laws_.size() - 1);
    named.emplace_back(std::min(a, b), std::max(a, b));
  }
  // History pairs: every pair up to 5 fields, else the [[contact_pair]] ones.
  pair_index_.assign(static_cast<std::size_t>(n * n), -1);
  if (n <= 5) {
    for (int a = 0; a < n; ++a)
      for (int b = a + 1; b < n; ++b) pairs_.emplace_back(a, b);
  } else {
    pairs_ = named;
  }
  for (std::size_t k = 0; k < pairs_.size(); ++k) {
    pair_index_[static_cast<std::size_t>(pairs_[k].first * n + pairs_[k].second)] = static_cast<int>(k);
    pair_index_[static_cast<std::size_t>(pairs_[k].second * n + pairs_[k].first)] = static_cast<int>(k);
  }
  pair_force_.assign(pairs_.size(), Vec3::Zero());

  if (cfg_.normal == "specified") {
    for (int a = 0; a < D && a < static_cast<int>(cfg_.normal_direction.size()); ++a)
      specified_[a] = cfg_.normal_direction[static_cast<std::size_t>(a)];
    specified_.normalize();
  }
  need_clouds_ = cfg_.normal == "lr" || cfg_.normal == "linear" || cfg_.detection == "lr";
  need_gradient_ = cfg_.normal == "ag";
  need_position_ = cfg_.detection == "cp" || cfg_.detection == "df";
  need_radius_ = cfg_.detection == "lr";
  if (cfg_.detection == "df") {
    const int ppc = config.bodies.empty() ? 2 : config.bodies.front().particles_per_cell[0];
    df_table(config.method, ppc, df_s_, df_d_);
    if (df_s_.size() < 2) throw std::invalid_argument(where + ": detection = \"df\": no d(x) table for this shape family");
  }
  contact_of_.assign(static_cast<std::size_t>(n_nodes_), -1);
}

template <int D>
Contact<D>::~Contact() = default;

template <int D>
double Contact<D>::cell_width(const Vec3& n) const {
  double hn2 = 0.0;
  for (int a = 0; a < D; ++a) hn2 += n[a] * n[a] * grid_->cell_size()[a] * grid_->cell_size()[a];
  return std::sqrt(hn2);
}

template <int D>
double Contact<D>::contact_area(const Vec3& n) const {
  // A_c = V_cell / h_n: the cell's cross-section normal to n for square cells (thickness in 2D,
  // cross-section in 1D included through the cell volume).
  double volume = 1.0;
  for (int a = 0; a < D; ++a) volume *= grid_->cell_size()[a];
  const double hn = cell_width(n);
  return hn > 0.0 ? volume / hn : 0.0;
}

template <int D>
double Contact<D>::edge_distance(double s) const {
  // d(s) by linear interpolation in the table, linear extrapolation beyond it.
  const std::size_t n = df_s_.size();
  std::size_t k = static_cast<std::size_t>(std::upper_bound(df_s_.begin(), df_s_.end(), s) - df_s_.begin());
  k = std::clamp<std::size_t>(k, 1, n - 1);
  const double t = (s - df_s_[k - 1]) / (df_s_[k] - df_s_[k - 1]);
  return df_d_[k - 1] + t * (df_d_[k] - df_d_[k - 1]);
}

template <int D>
void Contact<D>::prepare(const Particles<D>& particles, const TransferCache<D>& cache, const std::vector<double>& mass) {
  const ScopedSeconds lap(prepare_seconds_);
  const int nf = n_fields();
  // Contact nodes: two or more fields with mass.
  for (std::int32_t c : nodes_) contact_of_[static_cast<std::size_t>(c)] = -1;
  nodes_.clear();
  field_begin_.assign(1, 0);
  fields_.clear();
  for (std::int32_t i = 0; i < n_nodes_; ++i) {
    int present = 0;
    for (int f = 0; f < nf; ++f) present += mass[static_cast<std::size_t>(f * n_nodes_ + i)] > small_mass_;
    if (present < 2) continue;
    contact_of_[static_cast<std::size_t>(i)] = static_cast<std::int32_t>(nodes_.size());
    nodes_.push_back(i);
    for (int f = 0; f < nf; ++f)
      if (mass[static_cast<std::size_t>(f * n_nodes_ + i)] > small_mass_) fields_.push_back(f);
    field_begin_.push_back(static_cast<std::int32_t>(fields_.size()));
  }
  const std::size_t nc = nodes_.size();
  // Interactions: one per node for two fields; per field (lumped) or per pair at 3+ nodes.
  inter_begin_.assign(1, 0);
  inter_.clear();
  const bool pairs_mode = cfg_.three_or_more == "pairs";
  for (std::size_t c = 0; c < nc; ++c) {
    const int b0 = field_begin_[c], b1 = field_begin_[c + 1];
    if (b1 - b0 == 2 || pairs_mode) {
      for (int x = b0; x < b1; ++x)
        for (int y = x + 1; y < b1; ++y) {
          Interaction it;
          it.a = fields_[static_cast<std::size_t>(x)];
          it.b = fields_[static_cast<std::size_t>(y)];
          it.law = law_of(it.a, it.b);
          inter_.push_back(it);
        }
    } else {
      for (int x = b0; x < b1; ++x) {
        Interaction it;
        it.a = fields_[static_cast<std::size_t>(x)];
        it.b = -1;
        inter_.push_back(it);
      }
    }
    inter_begin_.push_back(static_cast<std::int32_t>(inter_.size()));
  }
  node_steps_ += static_cast<long long>(nc);
  // A node-halo run's neighbours exchange below whether this rank has contact nodes or not.
  const bool halo = halo_ != nullptr && halo_->n_neighbours() > 0;
  if (nc == 0 && !halo) return;

  const std::size_t n_slots = static_cast<std::size_t>(nf) * static_cast<std::size_t>(n_nodes_);
  // Grid extrapolations for AG normals (Eq. 11: g = sum G V) and CP/DF positions (x = S+ X).
  if (need_gradient_ || need_position_) {
    if (need_gradient_) gradient_.assign(n_slots, Vec<D>::Zero());
    if (need_position_) position_.assign(n_slots, Vec<D>::Zero());
    scatter(cache, [&](std::int32_t p, const auto& stencil) {
      const std::int32_t off = field_of(particles, static_cast<std::size_t>(p)) * n_nodes_;
      stencil.for_each([&](std::int32_t node, double S, const Vec<D>& G) {
        const std::int32_t slot = node + off;
        if (contact_of_[static_cast<std::size_t>(node)] < 0) return;
        if (need_gradient_) {
          const double V = particles.volume0[p] * particles.deformation_gradient[p].determinant();
          gradient_[static_cast<std::size_t>(slot)] += V * G;
        }
        if (need_position_)
          position_[static_cast<std::size_t>(slot)] +=
              (S * particles.mass[p]) * offset_from_node(*grid_, node, particles.position[p]);
      });
    });
    // Node halo: the other ranks' particles add their parts at the shared nodes, as to the mass.
    if (halo) {
      if (need_gradient_ && need_position_) halo_->sum(nf, gradient_, position_);
      else if (need_gradient_) halo_->sum(nf, gradient_);
      else halo_->sum(nf, position_);
    }
  }
  if (need_clouds_) build_clouds(particles, cache);
  if (nc == 0) return;
  // Normals and separations, node by node.
  const ScopedSeconds fit_lap(fit_seconds_);
  const auto n_contact = static_cast<std::int64_t>(nc);
#pragma omp parallel
  {
    std::vector<Vec3> cloud_x;
    std::vector<signed char> cloud_c;
    std::vector<std::int32_t> cloud_p;
    std::vector<double> cloud_w;
#pragma omp for schedule(dynamic, 16)
    for (std::int64_t c = 0; c < n_contact; ++c)
      for (std::int32_t k = inter_begin_[static_cast<std::size_t>(c)]; k < inter_begin_[static_cast<std::size_t>(c) + 1]; ++k)
        geometry(static_cast<std::size_t>(c), particles, mass, cloud_x, cloud_c, cloud_p, cloud_w,
                 inter_[static_cast<std::size_t>(k)]);
  }
}

template <int D>
void Contact<D>::build_clouds(const Particles<D>& particles, const TransferCache<D>& cache) {
  // Point clouds: the particles whose stencil holds the contact node (seed 004 Sec. 3.1, Fig. 3A).
  const std::size_t nc = nodes_.size();
  const auto np = static_cast<std::int64_t>(particles.n());
  // Node halo: the other ranks' particles at the contact nodes this window shares with theirs.
  ghost_node_.clear();
  ghost_ref_.clear();
  ghost_weight_.clear();
  ghosts_.clear();
  const bool halo = halo_ != nullptr && halo_->n_neighbours() > 0;
  if (halo) exchange_cloud_particles(particles, cache, ghost_node_, ghost_ref_, ghost_weight_);
  cloud_begin_.assign(nc + 1, 0);
  // Particles in increasing id (a distributed run's ghosts included; a serial run's particles
  // kept in cell-block order), as in a serial run in creation order. (Under a node halo each
  // cloud is sorted by id below, with the other ranks' particles.)
  const bool own_order = !halo && cache.sorted_storage && cache.id_order.empty();
  if (own_order) storage_in_id_order(particles, id_order_);
  const std::vector<std::int32_t>& ids = own_order ? id_order_ : cache.id_order;
  auto particle_at = [&](std::int64_t k) { return ids.empty() ? k : std::int64_t{ids[static_cast<std::size_t>(k)]}; };
  for (std::int64_t p = 0; p < np; ++p)
    for_each_entry(cache, static_cast<std::size_t>(p), [&](std::int32_t node, double S, const Vec<D>&) {
      const std::int32_t c = contact_of_[static_cast<std::size_t>(node)];
      if (c >= 0 && S > 0.0) ++cloud_begin_[static_cast<std::size_t>(c) + 1];
    });
  for (std::int32_t c : ghost_node_) ++cloud_begin_[static_cast<std::size_t>(c) + 1];
  for (std::size_t c = 0; c < nc; ++c) cloud_begin_[c + 1] += cloud_begin_[c];
  cloud_.resize(static_cast<std::size_t>(cloud_begin_[nc]));
  cloud_weight_.resize(cloud_.size());
  std::vector<std::int32_t>& cursor = cloud_cursor_;
  cursor.assign(cloud_begin_.begin(), cloud_begin_.end() - 1);
  for (std::int64_t k = 0; k < np; ++k) {
    const std::int64_t p = particle_at(k);
    for_each_entry(cache, static_cast<std::size_t>(p), [&](std::int32_t node, double S, const Vec<D>&) {
      const std::int32_t c = contact_of_[static_cast<std::size_t>(node)];
      if (c >= 0 && S > 0.0) {
        const auto at = static_cast<std::size_t>(cursor[static_cast<std::size_t>(c)]++);
        cloud_[at] = static_cast<std::int32_t>(p);
        cloud_weight_[at] = S;
      }
    });
  }
  if (!halo) return;
  for (std::size_t e = 0; e < ghost_node_.size(); ++e) {
    const auto at = static_cast<std::size_t>(cursor[static_cast<std::size_t>(ghost_node_[e])]++);
    cloud_[at] = ghost_ref_[e];
    cloud_weight_[at] = ghost_weight_[e];
  }
  // Every cloud in increasing id: the order of the serial run, and the same on every rank that
  // holds the node, so that all copies of a shared node fit the same points in the same order
  // and get the same bits.
  auto& order = sort_order_;
  auto& refs = sort_refs_;
  auto& weights = sort_weights_;
  for (std::size_t c = 0; c < nc; ++c) {
    const auto b = static_cast<std::size_t>(cloud_begin_[c]), e = static_cast<std::size_t>(cloud_begin_[c + 1]);
    order.clear();
    for (std::size_t k = b; k < e; ++k)
      order.emplace_back(cloud_id(particles, cloud_[k]), static_cast<std::int32_t>(k - b));
    std::stable_sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    refs.assign(cloud_.begin() + static_cast<std::ptrdiff_t>(b), cloud_.begin() + static_cast<std::ptrdiff_t>(e));
    weights.assign(cloud_weight_.begin() + static_cast<std::ptrdiff_t>(b),
                   cloud_weight_.begin() + static_cast<std::ptrdiff_t>(e));
    for (std::size_t k = b; k < e; ++k) {
      const auto from = static_cast<std::size_t>(order[k - b].second);
      cloud_[k] = refs[from];
      cloud_weight_[k] = weights[from];
    }
  }
}

namespace {

template <class T>
void put(std::vector<char>& out, const T& value) {
  const auto at = out.size();
  out.resize(at + sizeof(T));
  std::memcpy(out.data() + at, static_cast<const void*>(&value), sizeof(T));
}

template <class T>
T take(const char*& at, const char* end) {
  if (static_cast<std::size_t>(end - at) < sizeof(T))
    throw std::runtime_error("contact: a neighbour's message of cloud particles ends early");
  T value;
  std::memcpy(static_cast<void*>(&value), at, sizeof(T));
  at += sizeof(T);
  return value;
}

}  // namespace

template <int D>
void Contact<D>::exchange_cloud_particles(const Particles<D>& particles, const TransferCache<D>& cache,
                                          std::vector<std::int32_t>& entry_node, std::vector<std::int32_t>& entry_ref,
                                          std::vector<double>& entry_weight) {
  // The point cloud of a node is every particle whose stencil holds it. Such a particle of
  // another rank reaches this window only at a node both windows hold (its stencil lies in its
  // own rank's window), and the ranks agree on which shared nodes are contact nodes (their node
  // masses are the same bits after the halo sum). So each rank sends each neighbour, once per
  // particle, what the fits read of its particles that reach their shared contact nodes -- id,
  // field, position (and F and the initial size for LR separations) -- with the rows of those
  // nodes in the shared list and the weights S_ip: a band one stencil wide around the contact
  // nodes on the rank boundary, not the whole ghost band of the particle halo.
  const std::size_t nk = halo_->n_neighbours();
  cloud_send_.resize(nk);
  for (auto& b : cloud_send_) b.clear();
  auto& entries = halo_entries_;
  for (std::size_t p = 0; p < particles.n(); ++p) {
    entries.clear();
    for_each_entry(cache, p, [&](std::int32_t node, double S, const Vec<D>&) {
      if (!(S > 0.0) || contact_of_[static_cast<std::size_t>(node)] < 0) return;
      for (const auto& h : halo_->holders_of(node)) entries.push_back({h.k, static_cast<std::int32_t>(h.s), S});
    });
    if (entries.empty()) continue;
    std::stable_sort(entries.begin(), entries.end(), [](const HaloEntry& a, const HaloEntry& b) { return a.k < b.k; });
    for (std::size_t i = 0; i < entries.size();) {
      std::size_t j = i;
      while (j < entries.size() && entries[j].k == entries[i].k) ++j;
      std::vector<char>& out = cloud_send_[entries[i].k];
      put(out, particles.id[p]);
      put(out, field_of(particles, p));
      put(out, static_cast<std::int32_t>(j - i));
      put(out, particles.position[p]);
      if (need_radius_) {
        put(out, particles.deformation_gradient[p]);
        put(out, edges(particles, p));
      }
      for (; i < j; ++i) {
        put(out, entries[i].row);
        put(out, entries[i].S);
      }
    }
  }
  const Comm::Buffers recv = halo_->exchange(cloud_send_);
  for (std::size_t k = 0; k < nk; ++k) {
    const std::vector<std::int32_t>& shared = halo_->shared_with(k);
    const char* at = recv[k].data();
    const char* const end = at + recv[k].size();
    while (at < end) {
      const auto g = static_cast<std::int32_t>(ghosts_.id.size());
      ghosts_.id.push_back(take<std::int64_t>(at, end));
      ghosts_.field.push_back(take<std::int32_t>(at, end));
      const auto n = take<std::int32_t>(at, end);
      ghosts_.position.push_back(take<Vec<D>>(at, end));
      if (need_radius_) {
        ghosts_.deformation_gradient.push_back(take<Mat3>(at, end));
        ghosts_.size0.push_back(take<Vec<D>>(at, end));
      }
      for (std::int32_t e = 0; e < n; ++e) {
        const auto row = take<std::int32_t>(at, end);
        const double S = take<double>(at, end);
        const std::int32_t c = row >= 0 && static_cast<std::size_t>(row) < shared.size()
                                   ? contact_of_[static_cast<std::size_t>(shared[static_cast<std::size_t>(row)])]
                                   : -1;
        if (c < 0)
          throw std::runtime_error(fmt::format("contact: rank {} sent a cloud particle for shared node row {}, which "
                                               "is no contact node here (the node halo is out of step)",
                                               halo_->neighbour(k), row));
        entry_node.push_back(c);
        entry_ref.push_back(-1 - g);
        entry_weight.push_back(S);
      }
    }
  }
}

template <int D>
void Contact<D>::geometry(std::size_t c, const Particles<D>& particles, const std::vector<double>& mass,
                          std::vector<Vec3>& cloud_x, std::vector<signed char>& cloud_c,
                          std::vector<std::int32_t>& cloud_p, std::vector<double>& cloud_w, Interaction& it) const {
  const std::int32_t node = nodes_[c];
  const int nf = n_fields();
  auto in_beta = [&](std::int32_t f) { return it.b < 0 ? f != it.a : f == it.b; };
  auto slot = [&](std::int32_t f) { return static_cast<std::size_t>(f * n_nodes_ + node); };
  const int b0 = field_begin_[c], b1 = field_begin_[c + 1];

  // Point cloud of alpha (-1) and beta (+1), positions relative to the node.
  if (need_clouds_) {
    cloud_x.clear();
    cloud_c.clear();
    cloud_p.clear();
    cloud_w.clear();
    for (std::int32_t k = cloud_begin_[c]; k < cloud_begin_[c + 1]; ++k) {
      const std::int32_t p = cloud_[static_cast<std::size_t>(k)];
      const std::int32_t f = cloud_field(particles, p);
      signed char cls = 0;
      if (f == it.a) cls = -1;
      else if (in_beta(f)) cls = 1;
      else continue;
      cloud_x.push_back(to3<D>(offset_from_node(*grid_, node, cloud_position(particles, p))));
      cloud_c.push_back(cls);
      cloud_p.push_back(p);
      cloud_w.push_back(cloud_weight_[static_cast<std::size_t>(k)]);
    }
  }

  // ---- normal, from alpha to beta
  Vec3 n = Vec3::Zero();
  if (cfg_.normal == "specified") {
    n = specified_;
    if (it.b >= 0 ? it.a > it.b : false) n = -n;  // points from the lower-numbered field
    if (it.b < 0) {  // lumped: alpha against the rest; lowest-numbered field present is "first"
      if (it.a != fields_[static_cast<std::size_t>(b0)]) n = -n;
    }
  } else if (cfg_.normal == "ag") {
    Vec<D> ga = gradient_[slot(it.a)], gb = Vec<D>::Zero();
    for (int x = b0; x < b1; ++x) {
      const std::int32_t f = fields_[static_cast<std::size_t>(x)];
      if (in_beta(f)) gb += gradient_[slot(f)];
    }
    n = to3<D>(Vec<D>(ga - gb));  // seed 004 Eq. 13
    const double norm = n.norm();
    n = norm > 0.0 ? Vec3(n / norm) : Vec3::Zero();
  } else {
    contact::PlaneFitOptions opt;
    opt.dim = D;
    opt.cell_size = grid_->min_cell_size();
    // Point weights: each particle's shape-function weight S_ip at the node (lr_weights =
    // "shape"; docs/contact.md: a flat interface through a regular lattice then gets its exact
    // normal), or w_p = 1 (seed 004 Appendix).
    const auto weights = cfg_.lr_weights == "shape" ? std::span<const double>(cloud_w) : std::span<const double>();
    const auto fit = contact::fit_separating_plane(
        std::span<const Vec3>(cloud_x), std::span<const signed char>(cloud_c), weights,
        Vec3::Zero(), opt, cfg_.normal == "linear" ? contact::PlaneFitMethod::linear : contact::PlaneFitMethod::logistic);
    if (fit.ok) n = fit.normal;
    if (cfg_.lr_refine == "margin") {
      // Where the clouds are linearly separable, the widest-gap plane: the limit the logistic fit
      // tends to, free of its finite-scale tilt (docs/contact.md, "Flat interfaces").
      const auto mm = contact::max_margin_plane(std::span<const Vec3>(cloud_x), std::span<const signed char>(cloud_c), D);
      if (mm.ok) n = mm.normal;
    }
  }
  it.normal = n;
  it.area = contact_area(n);
  if (!(n.squaredNorm() > 0.0)) {  // no normal: treat as not touching unless bonded
    it.separation = std::numeric_limits<double>::infinity();
    return;
  }

  // ---- separation (< 0: touching)
  const std::string& det = cfg_.detection;
  if (det == "velocity") {
    it.separation = -1.0;  // Eq. 14 alone: approach decides
  } else if (det == "lr") {
    // Eq. 22-25: edges of the clouds along n with the deformed inscribed-ellipsoid radii.
    double max_a = -std::numeric_limits<double>::infinity(), min_b = std::numeric_limits<double>::infinity();
    // lr_separation = "column": only the particles within half a cell of the node's line along n.
    const double column = cfg_.lr_separation == "column" ? 0.5 * cell_width(n) : 0.0;
    for (std::size_t k = 0; k < cloud_x.size(); ++k) {
      const std::int32_t r = cloud_p[k];  // (p >= 0: this rank's particle, else ghost -1 - r)
      if (column > 0.0 && (cloud_x[k] - cloud_x[k].dot(n) * n).norm() > column) continue;
      const auto g = static_cast<std::size_t>(-1 - r);
      const Vec<D> size0 = r >= 0 ? edges(particles, static_cast<std::size_t>(r)) : ghosts_.size0[g];
      const Mat3& F = r >= 0 ? particles.deformation_gradient[static_cast<std::size_t>(r)] : ghosts_.deformation_gradient[g];
      Vec3 R0 = Vec3::Ones();
      for (int a = 0; a < D; ++a) R0[a] = 0.5 * size0[a];
      const double R = size0.isZero() ? 0.0 : contact::deformed_radius(F, R0, n, D);  // (a point: no radius)
      const double xn = cloud_x[k].dot(n);
      if (cloud_c[k] < 0) max_a = std::max(max_a, xn + R);
      else min_b = std::min(min_b, xn - R);
    }
    it.separation = min_b - max_a - cfg_.touching_tolerance * cell_width(n);
  } else {
    // Extrapolated centres x^a, x^b relative to the node (Eq. 11), lumped for beta when needed.
    Vec<D> xa = Vec<D>::Zero(), xb = Vec<D>::Zero();
    double ma = 0.0, mb = 0.0;
    for (int x = b0; x < b1; ++x) {
      const std::int32_t f = fields_[static_cast<std::size_t>(x)];
      const double m = mass[slot(f)];
      if (f == it.a) {
        xa += position_[slot(f)];
        ma += m;
      } else if (in_beta(f)) {
        xb += position_[slot(f)];
        mb += m;
      }
    }
    xa /= ma;
    xb /= mb;
    const double sa = to3<D>(xa).dot(n), sb = to3<D>(xb).dot(n);
    if (det == "cp") {
      // Eq. 16: (x^b - x^a).n < delta_c, delta_c in cells across the node along n.
      it.separation = (sb - sa) - cfg_.critical_separation * cell_width(n);
    } else {
      // Eq. 15: d(x^b) - d(x^a) with d from the family's table; beta mirrors alpha.
      const double h = cell_width(n);
      const double da = edge_distance(sa / h) * h;
      const double db = -edge_distance(-sb / h) * h;
      it.separation = db - da - cfg_.touching_tolerance * h;
    }
  }
  (void)nf;
}

template <int D>
void Contact<D>::correct(const std::vector<double>& mass, std::vector<Vec<D>>& values, bool momentum, Pass pass,
                         double time, double dt, std::vector<Vec<D>>* dv, std::vector<Vec<D>>* dv_impulse) {
  const std::size_t nc = nodes_.size();
  const bool record = pass == Pass::updated;
  const ScopedSeconds lap(correct_seconds_);
  if (record) {
    active_ = 0;
    pair_force_sum_.assign(3 * pairs_.size(), ExactSum());
    trace_.clear();
  }
  const bool tracing = record && tracing_;
  // Kinetic energy the change gives the fields at the nodes this rank owns (a correction that
  // reaches the particles: docs/contact.md, "Energy"), summed exactly like the forces.
  const bool count_energy = pass == Pass::updated || (pass == Pass::extrapolated && energy_from_first_);
  const bool energy_of_free_part = pass == Pass::extrapolated && impulse_;
  // Forces and counts sum over the nodes this rank owns (all of them in a serial run), exactly,
  // so that the totals do not depend on the partition (reduce() adds the ranks).
  auto add_force = [&](int pair, const Vec3& f) {
    for (int a = 0; a < 3; ++a) pair_force_sum_[static_cast<std::size_t>(3 * pair + a)].add(f[a]);
  };
  const int nf = n_fields();
  constexpr int max_local = 64;
  std::array<Vec3, max_local> p, dp_total, dp_free;  // dp_free: the part from non-bonded laws
  std::array<double, max_local> m;
  for (std::size_t c = 0; c < nc; ++c) {
    const std::int32_t node = nodes_[c];
    const bool counted = record && grid_->owns(node);
    const int b0 = field_begin_[c], b1 = field_begin_[c + 1];
    const int k = b1 - b0;
    if (k > max_local) throw std::runtime_error("contact: more than 64 fields at one node");
    auto slot = [&](int x) { return static_cast<std::size_t>(fields_[static_cast<std::size_t>(x)] * n_nodes_ + node); };
    auto local = [&](std::int32_t f) {
      for (int x = b0; x < b1; ++x)
        if (fields_[static_cast<std::size_t>(x)] == f) return x - b0;
      return -1;
    };
    for (int x = b0; x < b1; ++x) {
      const std::size_t s = slot(x);
      m[x - b0] = mass[s];
      p[x - b0] = to3<D>(momentum ? values[s] : Vec<D>(values[s] * mass[s]));
      dp_total[x - b0].setZero();
      dp_free[x - b0].setZero();
    }
    bool changed = false;
    const int i0 = inter_begin_[c], i1 = inter_begin_[c + 1];
    const bool lumped = i1 > i0 && inter_[static_cast<std::size_t>(i0)].b < 0;
    // One interaction: dp of alpha from the pair's law if bonded or in contact.
    auto change = [&](const Interaction& it, const Vec3& pa, double ma, const Vec3& pb, double mb, int law) -> Vec3 {
      const double mt = ma + mb;
      if (!(ma > 0.0 && mb > 0.0)) return Vec3::Zero();
      ContactInput in;
      in.dp0 = (ma / mt) * (pa + pb) - pa;  // m_a (v_cm - v_a), Eq. 8
      in.normal = it.normal;
      in.reduced_mass = ma * mb / mt;
      in.area = it.area;
      in.dt = dt;
      in.time = time;
      const ContactLaw& L = *laws_[static_cast<std::size_t>(law)];
      using S = typename NodeTrace::State;
      auto traced = [&](S state, const Vec3& d) {
        if (tracing) trace_.push_back({node, it.a, it.b, state, it.normal, it.separation, it.area, in.dp0, d});
        return d;
      };
      if (L.bonded()) return traced(S::bonded, in.dp0);
      // Contact needs approach, (v_b - v_a).n < 0 (Eq. 14), and touching (separation < 0).
      if (!(it.normal.squaredNorm() > 0.0)) return traced(S::no_normal, Vec3::Zero());
      if (!(in.dp0.dot(it.normal) < 0.0)) return traced(S::separating, Vec3::Zero());
      // release = "separation": a pair in contact at the last step's second correction stays in
      // contact while it approaches; the separation decides only when contact begins.
      const std::int64_t key = release_by_separation_ ? pair_key(node, it.a, it.b) : 0;
      if (!(it.separation < 0.0) && !(release_by_separation_ && in_contact_.count(key)))
        return traced(S::gap_open, Vec3::Zero());
      if (release_by_separation_ && record) in_contact_next_.insert(key);
      const Vec3 d = L.momentum_change(in);
      return traced((d - in.dp0).squaredNorm() == 0.0 ? S::stick : S::slip, d);
    };
    if (lumped) {
      // Eq. 50: each field against all others lumped; the change goes to that field only.
      for (int x = i0; x < i1; ++x) {
        const Interaction& it = inter_[static_cast<std::size_t>(x)];
        const int la = local(it.a);
        Vec3 pb = Vec3::Zero();
        double mb = 0.0, m_big = -1.0;
        int other = -1;
        for (int y = 0; y < k; ++y) {
          if (y == la) continue;
          pb += p[y];
          mb += m[y];
          if (m[y] > m_big) {
            m_big = m[y];
            other = fields_[static_cast<std::size_t>(b0 + y)];
          }
        }
        const Vec3 d = change(it, p[la], m[la], pb, mb, law_of(it.a, other));
        dp_total[la] = d;
        if (!laws_[static_cast<std::size_t>(law_of(it.a, other))]->bonded()) dp_free[la] = d;
        if (d.squaredNorm() > 0.0) {
          changed = true;
          if (counted) {
            const int pi = pair_index_[static_cast<std::size_t>(it.a * nf + other)];
            if (pi >= 0) add_force(pi, (it.a < other ? 1.0 : -1.0) * d / dt);
          }
        }
      }
    } else {
      // Two fields (one interaction), or the pairs of a 3+ node swept until they agree.
      const int n_inter = i1 - i0;
      if (n_inter > max_local) throw std::runtime_error("contact: more than 64 field pairs at one node");
      std::array<Vec3, max_local> inter_dp;
      for (int x = 0; x < n_inter; ++x) inter_dp[x].setZero();
      const int sweeps = n_inter == 1 ? 1 : 20;
      for (int sweep = 0; sweep < sweeps; ++sweep) {
        double biggest = 0.0, scale = 0.0;
        for (int x = i0; x < i1; ++x) {
          const Interaction& it = inter_[static_cast<std::size_t>(x)];
          const int la = local(it.a), lb = local(it.b);
          const Vec3 d = change(it, p[la] + dp_total[la], m[la], p[lb] + dp_total[lb], m[lb], it.law);
          dp_total[la] += d;
          dp_total[lb] -= d;
          if (!laws_[static_cast<std::size_t>(it.law)]->bonded()) {
            dp_free[la] += d;
            dp_free[lb] -= d;
          }
          inter_dp[x - i0] += d;
          biggest = std::max(biggest, d.norm());
          scale = std::max(scale, p[la].norm() + p[lb].norm());
        }
        if (biggest <= 1e-13 * scale) break;
      }
      for (int y = 0; y < k; ++y) changed = changed || dp_total[y].squaredNorm() > 0.0;
      if (counted && changed)
        for (int x = i0; x < i1; ++x) {
          const Interaction& it = inter_[static_cast<std::size_t>(x)];
          const int pi = pair_index_[static_cast<std::size_t>(it.a * nf + it.b)];
          if (pi >= 0) add_force(pi, (it.a < it.b ? 1.0 : -1.0) * inter_dp[x - i0] / dt);
        }
    }
    if (!changed) continue;
    if (counted) ++active_;
    if (count_energy && grid_->owns(node))
      for (int y = 0; y < k; ++y) {
        const Vec3& d = energy_of_free_part ? dp_free[y] : dp_total[y];
        if (!(m[y] > 0.0)) continue;
        if (pass == Pass::updated && start_velocity_) {
          // The work of the contact impulse at the step's mean grid velocity, as the external
          // work is measured: dp . (v + v+_corrected) / 2 with v+_corrected = v+ + dp / m.
          const Vec3 v0 = to3<D>((*start_velocity_)[slot(b0 + y)]);
          energy_change_.add(0.5 * d.dot(v0 + p[y] / m[y]) + 0.5 * d.squaredNorm() / m[y]);
        } else {
          // 1/2 m |v + dp/m|^2 - 1/2 m |v|^2 = dp.v + |dp|^2 / (2m) (an impulse on the particles)
          energy_change_.add(d.dot(p[y]) / m[y] + 0.5 * d.squaredNorm() / m[y]);
        }
      }
    for (int x = b0; x < b1; ++x) {
      const std::size_t s = slot(x);
      const Vec3& d = dp_total[x - b0];
      Vec<D> dD;
      for (int a = 0; a < D; ++a) dD[a] = d[a];
      if (momentum) values[s] += dD;
      else values[s] += dD / mass[s];
      if (dv) (*dv)[s] = dD / mass[s];
      if (dv_impulse) {
        Vec<D> fD;
        for (int a = 0; a < D; ++a) fD[a] = dp_free[x - b0][a];
        (*dv_impulse)[s] = fD / mass[s];
      }
    }
  }
  if (release_by_separation_ && record) {
    in_contact_.swap(in_contact_next_);
    in_contact_next_.clear();
  }
}

template <int D>
void Contact<D>::grid_changed() {
  n_nodes_ = grid_->n_nodes();
  nodes_.clear();
  contact_of_.assign(static_cast<std::size_t>(n_nodes_), -1);
}

template <int D>
void Contact<D>::reduce(const Comm& comm) {
  sum_across(comm, pair_force_sum_.data(), static_cast<int>(pair_force_sum_.size()));
  for (std::size_t k = 0; k < pairs_.size(); ++k)
    for (int a = 0; a < 3; ++a) pair_force_[k][a] = pair_force_sum_.empty() ? 0.0 : pair_force_sum_[3 * k + a].value();
  sum_across(comm, &energy_change_, 1);
  dissipated_ -= energy_change_.value();  // this step's passes, over every rank
  energy_change_ = ExactSum();
  std::int64_t counts[2] = {static_cast<std::int64_t>(active_), 0};
  for (std::int32_t c : nodes_) counts[1] += grid_->owns(c);
  comm.sum(counts, 2);
  active_total_ = static_cast<std::size_t>(counts[0]);
  contact_total_ = static_cast<std::size_t>(counts[1]);
}

template <int D>
void Contact<D>::node_normals(std::vector<Vec3>& out) const {
  out.assign(static_cast<std::size_t>(n_nodes_), Vec3::Zero());
  for (std::size_t c = 0; c < nodes_.size(); ++c) {
    const int i0 = inter_begin_[c];
    if (inter_begin_[c + 1] > i0) out[static_cast<std::size_t>(nodes_[c])] = inter_[static_cast<std::size_t>(i0)].normal;
  }
}

template class Contact<1>;
template class Contact<2>;
template class Contact<3>;

}  // namespace cairn
