// Update schemes and stress-update timings: the full-mass expansion converges to the exact
// full-mass solve; every scheme's A and VV match a hand-computed step; the dissipated-energy tally
// agrees with the particles' measured energy balance (FLIP none); APIC conserves angular
// momentum in a transfer round trip; every scheme and timing keeps a rigid translation rigid.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>

#include "../support/config_builder.hpp"
#include "cairn/input/names.hpp"
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

// ---------------------------------------------------------------------------------------------
// A hand-computed case: three particles on a 1D grid of linear hat functions (h = 0.25), with
// chosen masses, volumes, velocities, stresses and (for APIC) affine velocities. The test builds
// S, G, m, p, f and the full-mass inverse m~_k^-1 densely from their definitions (seed 000
// Table 1 and Eq. 1, the closed binomial form, not the code's recursion), applies each scheme's
// A and VV as the papers write them, and compares V^(n+1), X^(n+1) and the USL velocity gradient
// of one step of the simulation.
struct HandCase {
  static constexpr double h = 0.25, dt = 0.01;
  std::vector<double> x{0.30, 0.45, 0.60}, M{1.0, 2.0, 1.5}, V{1.0, -0.5, 2.0};
  std::vector<double> V0{0.10, 0.20, 0.15}, tau{40.0, -25.0, 15.0}, C{0.0, 0.0, 0.0};
  static constexpr int n_nodes = 5;  // nodes j = 0..4 at x = j h; 1, 2 and 3 carry mass
  Eigen::MatrixXd S, G;              // S(p, j) = hat function, G(p, j) = its slope

  void build() {
    const int np = static_cast<int>(x.size());
    S = Eigen::MatrixXd::Zero(np, n_nodes);
    G = Eigen::MatrixXd::Zero(np, n_nodes);
    for (int q = 0; q < np; ++q)
      for (int j = 0; j < n_nodes; ++j) {
        const double r = (x[q] - j * h) / h;
        if (std::abs(r) < 1.0) {
          S(q, j) = 1.0 - std::abs(r);
          G(q, j) = r > 0.0 ? -1.0 / h : 1.0 / h;
        }
      }
  }
};

struct HandExpected {
  std::vector<double> V, X, L, C;
};

// Runs one step of the case through the simulation; returns V, X, grad V and APIC's C.
HandExpected run_hand_case(const HandCase& hc, const std::string& update, int k, double beta = 0.99,
                           const std::string& blend_position = "grid") {
  Config cfg = test::box_config(1, "linear");
  cfg.grid.cell_size = {HandCase::h};
  cfg.grid.extent = {1.0};
  cfg.bodies[0].shape.min = {0.25};
  cfg.bodies[0].shape.max = {0.5};
  cfg.bodies[0].particles_per_cell = {3};
  cfg.method.update = update;
  cfg.method.order = k;
  cfg.method.plugin.set("beta", beta);
  cfg.method.plugin.set("blend_position", blend_position);
  Simulation<1> sim(cfg);
  auto& P = sim.particles();
  EXPECT_EQ(P.n(), hc.x.size());
  for (std::size_t q = 0; q < P.n(); ++q) {
    P.position[q][0] = hc.x[q];
    P.mass[q] = hc.M[q];
    P.volume0[q] = hc.V0[q];
    P.velocity[q][0] = hc.V[q];
    P.kirchhoff_stress[q] = Mat3::Zero();
    P.kirchhoff_stress[q](0, 0) = hc.tau[q];
    P.deformation_gradient[q] = Mat3::Identity();
    if (P.has_affine) {  // C_p is stored for APIC only (hc.C is zero for the other schemes)
      P.affine_velocity[q] = Mat3::Zero();
      P.affine_velocity[q](0, 0) = hc.C[q];
    }
  }
  sim.step(HandCase::dt);
  HandExpected out;
  for (std::size_t q = 0; q < P.n(); ++q) {
    out.V.push_back(P.velocity[q][0]);
    out.X.push_back(P.position[q][0]);
    // Particles keep no velocity gradient; from F = I the step made F = exp(L dt) (seed 000
    // Task 5), so L = ln(F_xx) / dt (round-off ~1e-16 / dt, far below the tolerance).
    out.L.push_back(std::log(P.deformation_gradient[q](0, 0)) / HandCase::dt);
    out.C.push_back(P.has_affine ? P.affine_velocity[q](0, 0) : 0.0);
  }
  return out;
}

// The hand computation. Grid vectors live on the five nodes; unused nodes have zero mass.
struct HandGrid {
  Eigen::VectorXd m, p, f, v, v_new;
  Eigen::MatrixXd S, G;
  Eigen::MatrixXd SpS;  // S+ S = m^-1 S^T M S on the massive nodes (zero rows elsewhere)

  explicit HandGrid(HandCase hc) {
    hc.build();
    S = hc.S;
    G = hc.G;
    const int n = HandCase::n_nodes, np = static_cast<int>(hc.x.size());
    m = p = f = v = v_new = Eigen::VectorXd::Zero(n);
    Eigen::MatrixXd Mfull = Eigen::MatrixXd::Zero(n, n);  // m~ = S^T M S
    for (int q = 0; q < np; ++q)
      for (int i = 0; i < n; ++i) {
        m[i] += S(q, i) * hc.M[q];
        // APIC momentum: S M (V + C (x_i - x_p)) (Jiang et al. 2015); C = 0 for the others.
        p[i] += S(q, i) * hc.M[q] * (hc.V[q] + hc.C[q] * (i * HandCase::h - hc.x[q]));
        f[i] -= hc.V0[q] * hc.tau[q] * G(q, i);  // seed 000 Table 1 Task 2
        for (int j = 0; j < n; ++j) Mfull(i, j) += hc.M[q] * S(q, i) * S(q, j);
      }
    SpS = Eigen::MatrixXd::Zero(n, n);
    for (int i = 0; i < n; ++i)
      if (m[i] > 0.0) {
        v[i] = p[i] / m[i];
        v_new[i] = (p[i] + f[i] * HandCase::dt) / m[i];
        SpS.row(i) = Mfull.row(i) / m[i];
      }
  }
  // seed 000 Eq. 1, closed form: m~_k^-1 q = sum_{l=1..k} (-1)^(l+1) C(k,l) (S+S)^(l-1) m^-1 q.
  Eigen::VectorXd full_inverse(const Eigen::VectorXd& q, int k) const {
    Eigen::VectorXd minv_q = Eigen::VectorXd::Zero(q.size());
    for (int i = 0; i < q.size(); ++i)
      if (m[i] > 0.0) minv_q[i] = q[i] / m[i];
    Eigen::VectorXd sum = Eigen::VectorXd::Zero(q.size()), power = minv_q;
    double binom = 1.0;
    for (int l = 1; l <= k; ++l) {
      binom = binom * (k - l + 1) / l;
      sum += ((l % 2) ? 1.0 : -1.0) * binom * power;
      power = SpS * power;
    }
    return sum;
  }
};

void expect_hand(const HandCase& hc, const HandExpected& got, const std::vector<double>& A_dt,
                 const std::vector<double>& VV, const Eigen::VectorXd& stress_velocity, const std::string& what) {
  const HandGrid g(hc);
  for (std::size_t q = 0; q < hc.x.size(); ++q) {
    // seed 000 Task 4: V <- V + A dt, X <- X + VV dt + A dt^2 / 2.
    const double V1 = hc.V[q] + A_dt[q];
    const double X1 = hc.x[q] + VV[q] * HandCase::dt + 0.5 * A_dt[q] * HandCase::dt;
    // seed 000 Task 5: grad V_p = sum_i v_i G_pi with the scheme's grid velocity.
    const double L = g.G.row(static_cast<int>(q)).dot(stress_velocity);
    EXPECT_NEAR(got.V[q], V1, 1e-12 * (1.0 + std::abs(V1))) << what << " particle " << q;
    EXPECT_NEAR(got.X[q], X1, 1e-14) << what << " particle " << q;
    EXPECT_NEAR(got.L[q], L, 1e-11 * (1.0 + std::abs(L))) << what << " particle " << q;
  }
}

TEST(Schemes, EverySchemeMatchesAHandComputedStep) {
  const HandCase hc;
  const HandGrid g(hc);
  const int np = 3;
  const Eigen::VectorXd Sv = g.S * g.v, Sv_new = g.S * g.v_new;
  const Eigen::VectorXd Sa_dt = Sv_new - Sv;
  // Sanity of the hand case itself: forces sum to zero, the grid moves the mass's momentum.
  EXPECT_NEAR(g.f.sum(), 0.0, 1e-12);
  EXPECT_GT(Sa_dt.cwiseAbs().minCoeff(), 1e-3);
  std::vector<double> V(hc.V), A, VV;
  auto fill = [&](auto a_dt, auto vv) {
    A.assign(np, 0.0);
    VV.assign(np, 0.0);
    for (int q = 0; q < np; ++q) {
      A[q] = a_dt(q);
      VV[q] = vv(q);
    }
  };
  // FLIP family (seed 000 Task 4; seed 002 Eq. 1.58, 1.60-1.65).
  fill([&](int q) { return Sa_dt[q]; }, [&](int q) { return Sv[q]; });
  expect_hand(hc, run_hand_case(hc, "flip", 1), A, VV, g.v_new, "flip");
  fill([&](int q) { return Sa_dt[q]; }, [&](int q) { return Sv[q] + 0.5 * Sa_dt[q]; });
  expect_hand(hc, run_hand_case(hc, "flip1", 1), A, VV, g.v_new, "flip1");
  fill([&](int q) { return Sa_dt[q]; }, [&](int q) { return V[q] + 0.5 * Sa_dt[q]; });
  expect_hand(hc, run_hand_case(hc, "flip2", 1), A, VV, g.v_new, "flip2");
  fill([&](int q) { return Sa_dt[q]; }, [&](int q) { return V[q]; });
  expect_hand(hc, run_hand_case(hc, "flip_vv", 1), A, VV, g.v_new, "flip_vv");
  // The three PIC updates of seed 000 Eq. 2: A dt = S m^-1 p+ - V; VV = (V(n+1) + V)/2, S m^-1 p, V.
  fill([&](int q) { return Sv_new[q] - V[q]; }, [&](int q) { return 0.5 * (Sv_new[q] + V[q]); });
  expect_hand(hc, run_hand_case(hc, "pic", 1), A, VV, g.v_new, "MPM PIC");
  fill([&](int q) { return Sv_new[q] - V[q]; }, [&](int q) { return Sv[q]; });
  expect_hand(hc, run_hand_case(hc, "xpic", 1), A, VV, g.v_new, "XPIC(1)");
  fill([&](int q) { return Sv_new[q] - V[q]; }, [&](int q) { return V[q]; });
  expect_hand(hc, run_hand_case(hc, "fmpm", 1), A, VV, g.v_new, "FMPM(1)");
  for (int k : {2, 3, 5}) {
    // XPIC(k): V(n+1) = S(m~_k^-1 p + m^-1 f dt), VV = S m^-1 p (seed 000 Sec. 2.3);
    // the stress update uses the lumped v+.
    const Eigen::VectorXd PV = g.S * g.full_inverse(g.p, k);
    fill([&](int q) { return PV[q] + Sa_dt[q] - V[q]; }, [&](int q) { return Sv[q]; });
    expect_hand(hc, run_hand_case(hc, "xpic", k), A, VV, g.v_new, "XPIC(" + std::to_string(k) + ")");
    // FMPM(k): v+ = m~_k^-1 p+, A dt = S v+ - V, VV = V; grad V from the same v+ (Table 1).
    const Eigen::VectorXd p_new = g.p + g.f * HandCase::dt;
    const Eigen::VectorXd v_full = g.full_inverse(p_new, k);
    const Eigen::VectorXd Sv_full = g.S * v_full;
    fill([&](int q) { return Sv_full[q] - V[q]; }, [&](int q) { return V[q]; });
    expect_hand(hc, run_hand_case(hc, "fmpm", k), A, VV, v_full, "FMPM(" + std::to_string(k) + ")");
    // The expansion must matter in this case, or the comparison above would not see k.
    EXPECT_GT((g.full_inverse(p_new, k) - g.full_inverse(p_new, 1)).cwiseAbs().maxCoeff(), 1e-3) << k;
    // Blend (seed 002 Eq. 1.79-1.80, 1.91-1.92) with the XPIC(k) projector P V = S m~_k^-1 p.
    const double beta = 0.7;
    fill([&](int q) { return (1.0 - beta) * (PV[q] - V[q]) + Sa_dt[q]; }, [&](int q) { return Sv[q]; });
    expect_hand(hc, run_hand_case(hc, "blend", k, beta, "grid"), A, VV, g.v_new, "blend grid");
    fill([&](int q) { return (1.0 - beta) * (PV[q] - V[q]) + Sa_dt[q]; },
         [&](int q) { return beta * Sv[q] + (1.0 - beta) * PV[q]; });
    expect_hand(hc, run_hand_case(hc, "blend", k, beta, "projected"), A, VV, g.v_new, "blend projected");
  }
  // APIC with a non-zero affine velocity: p includes M C (x_i - x_p); G2P is a PIC update with
  // X += S v+ dt, and the new C = sum_i S v+_i d / sum_i S d^2 with d = x_i - x_p.
  HandCase ha;
  ha.C = {0.8, -1.2, 0.5};
  const HandGrid ga(ha);
  const Eigen::VectorXd Sa_new = ga.S * ga.v_new;
  fill([&](int q) { return Sa_new[q] - ha.V[q]; }, [&](int q) { return 0.5 * (Sa_new[q] + ha.V[q]); });
  const HandExpected apic = run_hand_case(ha, "apic", 1);
  expect_hand(ha, apic, A, VV, ga.v_new, "APIC");
  for (int q = 0; q < np; ++q) {
    double B = 0.0, Dp = 0.0;
    for (int i = 0; i < HandCase::n_nodes; ++i) {
      const double d = i * HandCase::h - ha.x[q];
      B += ga.S(q, i) * ga.v_new[i] * d;
      Dp += ga.S(q, i) * d * d;
    }
    EXPECT_NEAR(apic.C[q], B / Dp, 1e-10 * (1.0 + std::abs(B / Dp))) << "APIC C, particle " << q;
  }
  // The affine part changes the momenta, so APIC must differ from PIC here.
  EXPECT_GT(std::abs(apic.V[0] - run_hand_case(ha, "pic", 1).V[0]), 1e-6);
}

TEST(Schemes, DissipatedEnergyAgreesWithTheParticleEnergyBalance) {
  // seed 002 Eq. 1.44-1.46 measured from the particles' motion, independently of the scheme's
  // A and VV: the non-dissipative FLIP change M Sa dt . (Sv + Sa dt / 2) minus the actual change
  // M dV . dX / dt. FLIP's tally must vanish by this measure; PIC's must agree with the code's.
  for (std::string update : {"flip", "pic", "xpic", "fmpm"}) {
    Simulation<2> sim(moving_block(update, 2));
    double independent = 0.0, flip_change = 0.0;
    for (int s = 0; s < 20; ++s) {
      const auto X0 = sim.particles().position;
      const auto V0 = sim.particles().velocity;
      const double dt = sim.next_dt();
      sim.step(dt);
      const auto& P = sim.particles();
      const auto& c = sim.cache();  // the stencils of the step just taken
      for (std::size_t q = 0; q < P.n(); ++q) {
        Vec<2> Sv = Vec<2>::Zero(), Sv_new = Vec<2>::Zero();
        for_each_entry(c, q, [&](std::int32_t node, double S, const Vec<2>&) {
          Sv += S * sim.nodes().velocity[node];
          Sv_new += S * sim.nodes().velocity_new[node];
        });
        const Vec<2> Sa_dt = Sv_new - Sv, dV = P.velocity[q] - V0[q], dX = P.position[q] - X0[q];
        const double flip = P.mass[q] * Sa_dt.dot(Sv + 0.5 * Sa_dt);
        independent += flip - P.mass[q] * dV.dot(dX) / dt;
        flip_change += std::abs(flip);
      }
    }
    ASSERT_GT(flip_change, 1e-8) << update;
    if (update == "flip") {
      EXPECT_NEAR(independent, 0.0, 1e-12 * flip_change);
      EXPECT_NEAR(sim.dissipated_energy(), 0.0, 1e-12 * flip_change);
    } else {
      EXPECT_GT(independent, 1e-3 * flip_change) << update;
      EXPECT_NEAR(sim.dissipated_energy(), independent, 1e-10 * flip_change) << update;
    }
  }
}

TEST(Schemes, BlendWithBetaOneIsFlip) {
  // seed 002 Eq. 1.79: beta = 1 leaves only the FLIP part, for any projector order.
  Config a = moving_block("flip"), b = moving_block("blend", 3);
  b.method.plugin.set("beta", 1.0);
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
