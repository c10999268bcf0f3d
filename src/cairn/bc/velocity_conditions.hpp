// Grid velocity conditions of the input beyond the [boundary] faces (docs/boundary-conditions.md):
//   [[velocity]]  a node set (a grid face with the ghost nodes beyond it, a box, a plane or line of
//                 nodes, or their intersection) whose velocity component along a unit direction
//                 is prescribed as a function of time (seed 000 Sec. 2.4);
//   [[wall]]      moving walls with depth and velocity gradient (seed 000 Sec. 2.5, Eq. 4;
//                 bc/moving_wall.hpp).
//
// Each step, prepare() lists every prescribed (node, direction) with its start and end values;
// apply() imposes one of the two on a velocity field. Every place of the step that imposes the
// [boundary] faces imposes these too, right after them: the lumped correction of v and v+
// (Task 3), and the velocity, lumped, combined (seed 000 Eq. 3) and constrained methods of the
// full-mass expansion (Simulation::full_mass_velocity).
//
// Precedence: entries are imposed in order - [boundary] faces first, then [[velocity]] tables in
// input order, then [[wall]] tables in input order - so where two of them hold the same node
// along non-orthogonal directions the later one wins. The first time a pair of conditions meets
// like this, a note names them (take_notes(); the run prints it once).
//
// Reactions (seed 000 Sec. 2.4): f^(BC) = m a^(b) with a^(b) dt = (v^(b) - v^+UL . n) n, where
// v^+UL is measured from the corrected start velocity when the start velocity is constrained
// ([boundary] acceleration = zero), so that the reaction is the force the condition adds to the
// grid momentum over the step: m (v_end - v_start) / dt - f . n. Summed per condition; where
// conditions share a node, each records its own correction and the sum is the node's reaction.
#pragma once

#include <set>
#include <string>
#include <utility>
#include <vector>

#include "cairn/bc/grid_conditions.hpp"
#include "cairn/bc/moving_wall.hpp"
#include "cairn/bc/prescribed_velocity.hpp"
#include "cairn/bc/time_function.hpp"
#include "cairn/grid/grid.hpp"
#include "cairn/config/config.hpp"
#include "cairn/parallel/exact_sum.hpp"

namespace cairn {

template <int D>
class VelocityConditions {
 public:
  enum class When { start, end };

  VelocityConditions() = default;
  /// Select the node sets. Throws std::invalid_argument naming the table and its line when a
  /// [[velocity]] selects no node or an expression is bad.
  /// `require_nodes`: a [[velocity]] selecting no node of `grid` is an input error (the whole
  /// grid at setup; a distributed run's windows may hold none of a set's nodes).
  VelocityConditions(const Config& config, const Grid<D>& grid, const GridConditions<D>& faces,
                     bool require_nodes = true);
  /// Keep the run state of `old` (wall positions, reported conflicts, last reactions) when a
  /// distributed run stores another window of the grid.
  void take_state(VelocityConditions&& old);
  /// The ranks over which reactions and wall gradients are summed (default: one).
  void set_comm(const Comm& comm) { comm_ = comm; }

  [[nodiscard]] bool empty() const { return sets_.empty() && walls_.empty(); }
  /// Names of the conditions then the walls; the owner index of an entry points here.
  [[nodiscard]] const std::vector<std::string>& names() const { return names_; }
  /// Nodes selected by [[velocity]] table k.
  [[nodiscard]] const std::vector<std::int32_t>& set_nodes(std::size_t k) const { return sets_[k].nodes; }

  /// List this step's prescribed components: node-set values at t and t + dt; the walls' nodes,
  /// gradients and values (from the mass and momentum of the step's P2G). Notes conflicts.
  void prepare(const Grid<D>& grid, const NodeField<D>& nodes, double small_mass, double t, double dt);
  /// The step is done: walls move to their end-of-step positions.
  void finish_step();

  /// Impose the start or end values on one velocity field.
  void apply(std::vector<Vec<D>>& velocity, When when, std::int32_t offset = 0) const;
  /// Task 3: the end values on v+ with reactions, and (constrain_start) the start values on v.
  /// `offset`: the field of a multimaterial run (entries field * n_nodes + node); reactions are
  /// reset only when `reset_reactions` (the first field), so they sum over the fields.
  void apply_step(NodeField<D>& nodes, double dt, bool constrain_start, std::int32_t offset = 0,
                  bool reset_reactions = true);

  /// Sum the reactions of the last apply_step calls over the nodes each rank owns and over the
  /// ranks (collective); reactions() then holds them.
  void reduce_reactions();
  /// Reaction force of each condition/wall (names() order) in the last step (reduce_reactions).
  [[nodiscard]] const std::vector<Vec<D>>& reactions() const { return reactions_; }
  [[nodiscard]] const std::vector<MovingWall<D>>& walls() const { return walls_; }
  [[nodiscard]] std::vector<MovingWall<D>>& walls() { return walls_; }
  /// This step's entries (for tests and plots).
  [[nodiscard]] const std::vector<PrescribedVelocity<D>>& entries() const { return entries_; }
  /// Notes raised since the last call (each conflicting pair once per run).
  std::vector<std::string> take_notes() { return std::exchange(notes_, {}); }

 private:
  struct NodeSet {
    Vec<D> direction = Vec<D>::Zero();
    TimeFunction velocity;
    std::vector<std::int32_t> nodes;
  };
  void note_conflicts(const Grid<D>& grid);

  std::vector<NodeSet> sets_;
  std::vector<MovingWall<D>> walls_;
  std::vector<std::string> names_;
  std::vector<std::string> kinds_;  ///< "velocity condition" or "wall", per owner
  std::vector<PrescribedVelocity<D>> entries_;
  std::vector<Vec<D>> reactions_;
  std::vector<ExactSum> reaction_sum_;  ///< D per owner: this rank's share, exactly
  const Grid<D>* grid_ = nullptr;
  Comm comm_ = Comm::serial();
  std::vector<std::uint8_t> face_mask_;  ///< per node: components set by [boundary] faces
  std::vector<std::int32_t> claim_;      ///< per node: last entry of this step (scratch, -1)
  std::set<std::pair<int, int>> reported_;
  std::vector<std::string> notes_;
};

/// Into `held`, per node of a grid of `n_nodes` nodes, bit a set where imposing `faces` and then
/// `sets` (apply) sets component a of a velocity field: held face components, mirror ghosts,
/// node sets and walls; a direction off the axes sets every component it has. Left empty when
/// there is no condition; its storage is kept from step to step. Needs `sets` prepared for the
/// step (VelocityConditions::prepare).
template <int D>
void held_components(const GridConditions<D>& faces, const VelocityConditions<D>& sets, std::int32_t n_nodes,
                     std::vector<std::uint8_t>& held);

}  // namespace cairn
