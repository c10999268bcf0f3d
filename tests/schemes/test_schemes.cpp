// Update schemes and stress-update timings: the full-mass expansion converges to the exact
// full-mass solve; schemes that the papers say coincide do; APIC conserves angular momentum in
// a transfer round trip; FLIP dissipates nothing by the seed 002 measure; every scheme and
// timing keeps a rigid translation rigid.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include "../support/config_builder.hpp"
#include "cairn/sim/names.hpp"
#include "cairn/sim/simulation.hpp"
#include "cairn/transfer/transfer.hpp"

namespace cairn {
namespace {

Config moving_block(const std::string& update, int k = 1) {
  Config cfg = test::box_config(2, "bspline2", "neo_hookean");
  cfg.method.update = update;
  cfg.method.order = k;
  cfg.bodies[0].velocity = {"0.5*sin(3*Y)", "0.3*cos(2*X)"};
  return cfg;
}

TEST(FullMass, ExpansionConvergesToTheFullMassSolve) {
  // seed 000 Eq. 1: m~_k^-1 p -> m~^-1 p as k grows, with m~ = S^T M S built densely here.
  Config cfg = moving_block("fmpm", 1);
  Simulation<2> sim(cfg);
  sim.build_stencils();
  sim.particles_to_grid(true, false);
  const auto& c = sim.cache();
  const auto& P = sim.particles();
  const int n = sim.grid().n_nodes();
  std::vector<int> active, index(n, -1);
  for (int i = 0; i < n; ++i)
    if (sim.nodes().mass[i] > 0.0) {
      index[i] = static_cast<int>(active.size());
      active.push_back(i);
    }
  const int na = static_cast<int>(active.size());
  Eigen::MatrixXd M = Eigen::MatrixXd::Zero(na, na);
  Eigen::MatrixXd p = Eigen::MatrixXd::Zero(na, 2);
  for (std::size_t q = 0; q < P.n(); ++q) {
    const auto entries = stencil_entries(c, q);
    for (const auto& es : entries) {
      const int i = index[es.node];
      p.row(i) += es.weight * P.mass[q] * P.velocity[q].transpose();
      for (const auto& et : entries) M(i, index[et.node]) += P.mass[q] * es.weight * et.weight;
    }
  }
  const Eigen::MatrixXd exact = M.ldlt().solve(p);
  std::vector<Vec<2>> lumped(n, Vec<2>::Zero()), out(n, Vec<2>::Zero());
  for (int a = 0; a < na; ++a) lumped[active[a]] = p.row(a).transpose() / sim.nodes().mass[active[a]];
  Eigen::VectorXd m(na);
  for (int a = 0; a < na; ++a) m[a] = sim.nodes().mass[active[a]];
  // (a) The k-term expansion is exactly sum_{j<k} A^j m^-1 p with A = I - m^-1 m~ (seed 000 Eq. 1).
  const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(na, na) - m.cwiseInverse().asDiagonal() * M;
  Eigen::MatrixXd term = m.cwiseInverse().asDiagonal() * p, sum = term;
  for (int k = 1; k <= 6; ++k) {
    if (k > 1) {
      term = A * term;
      sum += term;
    }
    sim.full_mass_velocity(lumped, out, k);
    for (int a = 0; a < na; ++a)
      EXPECT_LT((out[active[a]] - sum.row(a).transpose()).norm(), 1e-12 * (1.0 + sum.cwiseAbs().maxCoeff())) << k;
  }
  // (b) It converges to the full-mass solve: the mass-weighted error falls with every k. The
  // modes of nodes with little mass converge slowly (A's spectral radius is close to 1 there).
  double previous = 1e300, first = 0.0;
  for (int k : {1, 2, 4, 8, 16, 32, 64}) {
    sim.full_mass_velocity(lumped, out, k);
    double err = 0.0;
    for (int a = 0; a < na; ++a) err += m[a] * (out[active[a]] - exact.row(a).transpose()).squaredNorm();
    err = std::sqrt(err / m.sum());
    std::printf("k = %2d  mass-weighted RMS error %.3e\n", k, err);
    EXPECT_LT(err, previous) << "k = " << k;
    if (k == 1) first = err;
    previous = err;
  }
  EXPECT_LT(previous, 0.25 * first);
}

TEST(Schemes, ThePicUpdatesShareTheirVelocityAndDifferInPosition) {
  // seed 000 Eq. 2: FMPM(1), XPIC(1) and MPM PIC have the same A; VV differs.
  std::vector<Particles<2>> after;
  for (std::string u : {"pic", "xpic", "fmpm"}) {
    Simulation<2> sim(moving_block(u, 1));
    sim.step(1e-4);
    after.push_back(sim.particles());
  }
  double dx = 0.0;
  for (std::size_t p = 0; p < after[0].n(); ++p) {
    EXPECT_LT((after[0].velocity[p] - after[1].velocity[p]).norm(), 1e-14);
    EXPECT_LT((after[0].velocity[p] - after[2].velocity[p]).norm(), 1e-14);
    dx = std::max(dx, (after[0].position[p] - after[2].position[p]).norm());
  }
  EXPECT_GT(dx, 1e-9);
}

TEST(Schemes, BlendWithBetaOneIsFlip) {
  Config a = moving_block("flip"), b = moving_block("blend", 3);
  b.method.beta = 1.0;
  Simulation<2> sa(a), sb(b);
  for (int s = 0; s < 5; ++s) {
    sa.step(1e-4);
    sb.step(1e-4);
  }
  for (std::size_t p = 0; p < sa.particles().n(); ++p) {
    EXPECT_LT((sa.particles().velocity[p] - sb.particles().velocity[p]).norm(), 1e-13);
    EXPECT_LT((sa.particles().position[p] - sb.particles().position[p]).norm(), 1e-15);
  }
}

TEST(Schemes, FlipDissipatesNothingAndPicDissipates) {
  Simulation<2> flip(moving_block("flip")), pic(moving_block("pic"));
  for (int s = 0; s < 20; ++s) {
    flip.step(flip.next_dt());
    pic.step(pic.next_dt());
  }
  EXPECT_NEAR(flip.dissipated_energy(), 0.0, 1e-15);
  EXPECT_GT(pic.dissipated_energy(), 1e-10);
}

double angular_momentum(const Particles<2>& P, const TransferCache<2>& c, const Grid<2>& g) {
  // x_p x M V_p plus the affine part M sum_i S (x_i - x_p) x C (x_i - x_p).
  double L = 0.0;
  for (std::size_t p = 0; p < P.n(); ++p) {
    L += P.mass[p] * (P.position[p][0] * P.velocity[p][1] - P.position[p][1] * P.velocity[p][0]);
    const Eigen::Matrix2d C = P.affine_velocity[p].topLeftCorner<2, 2>();
    for (const auto& e : stencil_entries(c, p)) {
      const Vec<2> d = g.node_position(e.node) - P.position[p];
      const Vec<2> u = C * d;
      L += P.mass[p] * e.weight * (d[0] * u[1] - d[1] * u[0]);
    }
  }
  return L;
}

TEST(Schemes, ApicRoundTripConservesAngularMomentum) {
  for (std::string shape : {"linear", "bspline2"}) {
    Config cfg = moving_block("apic");
    cfg.method.shape = shape;
    cfg.bodies[0].velocity = {"-(Y-0.5) + 0.3*sin(5*X)", "(X-0.5) + 0.2*Y*Y"};
    Simulation<2> sim(cfg);
    // Give the particles non-trivial affine matrices, then check P2G and G2P (no forces).
    for (std::size_t p = 0; p < sim.particles().n(); ++p) {
      sim.particles().affine_velocity[p](0, 1) = 0.3 + 0.1 * std::sin(double(p));
      sim.particles().affine_velocity[p](1, 0) = -0.7;
      sim.particles().affine_velocity[p](0, 0) = 0.05;
    }
    sim.build_stencils();
    const double L0 = angular_momentum(sim.particles(), sim.cache(), sim.grid());
    sim.particles_to_grid(true, false);
    double Lg = 0.0;
    for (std::int32_t i = 0; i < sim.grid().n_nodes(); ++i) {
      const Vec<2> x = sim.grid().node_position(i);
      const Vec<2>& q = sim.nodes().momentum[i];
      Lg += x[0] * q[1] - x[1] * q[0];
    }
    EXPECT_NEAR(Lg, L0, 1e-12 * std::abs(L0)) << shape;
    sim.update_grid(1e-30);  // v = v+ = m^-1 p: no force acts
    sim.update_particles(1e-30);
    const double L1 = angular_momentum(sim.particles(), sim.cache(), sim.grid());
    EXPECT_NEAR(L1, L0, 1e-10 * std::abs(L0)) << shape;
  }
}

TEST(Schemes, EverySchemeAndTimingKeepsARigidTranslationRigid) {
  for (const auto& update : update_scheme_names()) {
    for (const auto& timing : stress_update_names()) {
      Config cfg = test::box_config(2, "bspline2", "neo_hookean");
      cfg.method.update = update;
      cfg.method.order = 3;
      cfg.method.stress_update = timing;
      cfg.bodies[0].velocity = {"0.3", "-0.2"};
      Simulation<2> sim(cfg);
      for (int s = 0; s < 10; ++s) sim.step(sim.next_dt());
      for (std::size_t p = 0; p < sim.particles().n(); ++p) {
        ASSERT_LT((sim.particles().velocity[p] - Vec<2>(0.3, -0.2)).norm(), 1e-11) << update << " " << timing;
        ASSERT_LT((sim.particles().deformation_gradient[p] - Mat3::Identity()).norm(), 1e-11) << update << " " << timing;
      }
    }
  }
}

TEST(Schemes, CentralDifferenceStartsWithHalfTheAcceleration) {
  Config a = moving_block("flip1"), b = moving_block("flip1");
  b.method.time_integration = "central_difference";
  Simulation<2> sa(a), sb(b);
  const auto V0 = sa.particles().velocity;
  sa.step(1e-4);
  sb.step(1e-4);
  for (std::size_t p = 0; p < V0.size(); ++p) {
    const Vec<2> full = sa.particles().velocity[p] - V0[p], half = sb.particles().velocity[p] - V0[p];
    EXPECT_LT((half - 0.5 * full).norm(), 1e-12 + 1e-9 * full.norm());
  }
}

}  // namespace
}  // namespace cairn
