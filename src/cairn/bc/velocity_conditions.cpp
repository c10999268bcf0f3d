#include "cairn/bc/velocity_conditions.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

#include "cairn/config/errors.hpp"

namespace cairn {

template <int D>
VelocityConditions<D>::VelocityConditions(const Config& config, const Grid<D>& grid,
                                          const GridConditions<D>& faces, bool require_nodes)
    : grid_(&grid) {
  for (const auto& vc : config.velocity_conditions) {
    const std::string what = vc.where.str() + ": velocity condition '" + vc.name + "'";
    NodeSet set;
    for (int a = 0; a < D; ++a) set.direction[a] = vc.direction[a];
    if (!(set.direction.norm() > 0.0)) throw std::invalid_argument(what + ": direction is zero");
    set.direction.normalize();
    set.velocity = TimeFunction(vc.velocity, vc.table, config.constants, what);
    const IVec<D> n = grid.n_cells();
    for (std::int32_t i = 0; i < grid.n_nodes(); ++i) {
      const IVec<D> j = grid.multi_index(i);
      const Vec<D> x = grid.node_position(i);
      bool in = true;
      if (vc.face >= 0) {
        const int a = vc.face / 2;
        in = vc.face % 2 == 0 ? j[a] <= 0 : j[a] >= n[a];  // the face and the ghost nodes beyond
      }
      for (int a = 0; a < D && in && !vc.box_min.empty(); ++a) {
        const double tol = 1e-6 * grid.cell_size()[a];
        in = x[a] >= vc.box_min[a] - tol && x[a] <= vc.box_max[a] + tol;
      }
      if (in && vc.plane_axis >= 0)
        in = std::abs(x[vc.plane_axis] - vc.plane_at) <= 1e-6 * grid.cell_size()[vc.plane_axis];
      if (in) set.nodes.push_back(i);
    }
    if (set.nodes.empty() && require_nodes)
      throw InputError(vc.where.file, vc.where.line,
                       fmt::format("velocity[{}]", &vc - config.velocity_conditions.data()),
                       "a selection (face, box_min/box_max, plane_axis/plane_at) holding at least one grid node",
                       fmt::format("velocity condition '{}', which selects none", vc.name));
    sets_.push_back(std::move(set));
    names_.push_back(vc.name);
    kinds_.push_back("velocity condition");
  }
  for (const auto& wc : config.walls) {
    walls_.emplace_back(wc, grid, config.constants);
    names_.push_back(wc.name);
    kinds_.push_back("wall");
  }
  reactions_.assign(names_.size(), Vec<D>::Zero());
  reaction_sum_.assign(D * names_.size(), ExactSum());
  if (empty()) return;
  face_mask_.assign(grid.n_nodes(), 0);
  for (std::size_t k = 0; k < faces.nodes().size(); ++k) face_mask_[faces.nodes()[k]] |= faces.masks()[k];
  for (const auto& m : faces.mirrors()) face_mask_[m.node] = static_cast<std::uint8_t>((1u << D) - 1u);
  claim_.assign(grid.n_nodes(), -1);
}

template <int D>
void VelocityConditions<D>::prepare(const Grid<D>& grid, const NodeField<D>& nodes, double small_mass,
                                    double t, double dt) {
  if (empty()) return;
  entries_.clear();
  for (std::size_t k = 0; k < sets_.size(); ++k) {
    NodeSet& s = sets_[k];
    const double v0 = s.velocity(t), v1 = s.velocity(t + dt);
    for (std::int32_t i : s.nodes) entries_.push_back({i, static_cast<std::int32_t>(k), s.direction, v0, v1});
  }
  for (std::size_t w = 0; w < walls_.size(); ++w)
    walls_[w].prepare(grid, nodes, small_mass, t, dt, static_cast<std::int32_t>(sets_.size() + w), entries_, comm_);
  note_conflicts(grid);
}

template <int D>
void VelocityConditions<D>::note_conflicts(const Grid<D>& grid) {
  // Later entries win; say so once per pair that meets on a node along non-orthogonal directions.
  auto note = [&](int first, int second, std::int32_t node) {
    if (!reported_.insert({first, second}).second) return;
    const Vec<D> x = grid.node_position(node);
    std::string where;
    for (int a = 0; a < D; ++a) where += fmt::format("{}{:.6g}", a ? ", " : "", x[a]);
    const std::string a_name =
        first < 0 ? std::string("the [boundary] faces") : fmt::format("{} '{}'", kinds_[first], names_[first]);
    notes_.push_back(fmt::format(
        "note: {} '{}' and {} both set the velocity of node {} at ({}) along non-orthogonal "
        "directions; '{}' takes precedence there (order: [boundary] faces, [[velocity]], [[wall]], "
        "later tables last; docs/boundary-conditions.md). Said once for this pair.",
        kinds_[second], names_[second], a_name, grid.whole().node_index(grid.multi_index(node)), where,
        names_[second]));
  };
  for (std::size_t k = 0; k < entries_.size(); ++k) {
    const auto& e = entries_[k];
    const std::uint8_t mask = face_mask_[e.node];
    for (int a = 0; a < D && mask; ++a)
      if ((mask >> a & 1u) && std::abs(e.direction[a]) > 1e-12) {
        note(-1, e.owner, e.node);
        break;
      }
    const std::int32_t c = claim_[e.node];
    if (c >= 0 && entries_[c].owner != e.owner && std::abs(entries_[c].direction.dot(e.direction)) > 1e-12)
      note(entries_[c].owner, e.owner, e.node);
    claim_[e.node] = static_cast<std::int32_t>(k);
  }
  for (const auto& e : entries_) claim_[e.node] = -1;
}

template <int D>
void VelocityConditions<D>::finish_step() {
  for (auto& w : walls_) w.finish_step();
}

template <int D>
void VelocityConditions<D>::apply(std::vector<Vec<D>>& velocity, When when, std::int32_t offset) const {
  for (const auto& e : entries_) {
    Vec<D>& v = velocity[e.node + offset];
    v += ((when == When::start ? e.start : e.end) - v.dot(e.direction)) * e.direction;
  }
}

template <int D>
void VelocityConditions<D>::apply_step(NodeField<D>& nodes, double dt, bool constrain_start, std::int32_t offset,
                                       bool reset_reactions) {
  if (reset_reactions) reaction_sum_.assign(D * names_.size(), ExactSum());
  for (const auto& e : entries_) {
    const std::int32_t i = e.node + offset;
    const Vec<D>& n = e.direction;
    double shift = 0.0;
    if (constrain_start) {
      shift = e.start - nodes.velocity[i].dot(n);
      nodes.velocity[i] += shift * n;
    }
    // seed 000 Sec. 2.4: a^(b) dt = (v^(b) - v^+UL . n) n, v^+UL from the corrected start.
    const double before = nodes.velocity_new[i].dot(n) + shift;
    const Vec<D> reaction = (nodes.mass[i] * (e.end - before) / dt) * n;
    if (grid_->owns(e.node))
      for (int a = 0; a < D; ++a) reaction_sum_[static_cast<std::size_t>(D * e.owner + a)].add(reaction[a]);
    nodes.reaction[i] += reaction;
    nodes.velocity_new[i] += (e.end - nodes.velocity_new[i].dot(n)) * n;
  }
}

template <int D>
void VelocityConditions<D>::reduce_reactions() {
  if (names_.empty()) return;
  sum_across(comm_, reaction_sum_.data(), static_cast<int>(reaction_sum_.size()));
  for (std::size_t k = 0; k < names_.size(); ++k)
    for (int a = 0; a < D; ++a) reactions_[k][a] = reaction_sum_[D * k + a].value();
}

template <int D>
void VelocityConditions<D>::take_state(VelocityConditions&& old) {
  walls_ = std::move(old.walls_);
  reactions_ = std::move(old.reactions_);
  reaction_sum_ = std::move(old.reaction_sum_);
  reported_ = std::move(old.reported_);
  notes_ = std::move(old.notes_);
  comm_ = old.comm_;
}

template <int D>
void held_components(const GridConditions<D>& faces, const VelocityConditions<D>& sets, std::int32_t n_nodes,
                     std::vector<std::uint8_t>& held) {
  held.clear();
  if (faces.empty() && sets.empty()) return;
  held.resize(static_cast<std::size_t>(n_nodes), 0);
  // In the order apply() imposes them: the faces' held components; then every mirror ghost takes
  // its source's value with the crossed faces' normals negated, so it is set where the source is
  // held and along those normals, whatever was held there before (a source is never a ghost, so
  // the order of the mirrors does not matter); then each entry sets every component its
  // direction has.
  const auto& nodes = faces.nodes();
  for (std::size_t k = 0; k < nodes.size(); ++k) held[nodes[k]] |= faces.masks()[k];
  for (const auto& m : faces.mirrors()) held[m.node] = static_cast<std::uint8_t>(m.negate | held[m.source]);
  for (const auto& e : sets.entries())
    for (int a = 0; a < D; ++a)
      if (e.direction[a] != 0.0) held[e.node] |= static_cast<std::uint8_t>(1U << a);
}

template void held_components(const GridConditions<1>&, const VelocityConditions<1>&, std::int32_t,
                              std::vector<std::uint8_t>&);
template void held_components(const GridConditions<2>&, const VelocityConditions<2>&, std::int32_t,
                              std::vector<std::uint8_t>&);
template void held_components(const GridConditions<3>&, const VelocityConditions<3>&, std::int32_t,
                              std::vector<std::uint8_t>&);

template class VelocityConditions<1>;
template class VelocityConditions<2>;
template class VelocityConditions<3>;

}  // namespace cairn
