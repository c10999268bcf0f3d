// Whole-step throughput in particle-steps per second per core (the figure docs/performance.md
// records), for the two reference cases of the foundation:
//   * 2D plane strain, quadratic B-splines, neo-Hookean, 2x2 particles per cell;
//   * 3D, linear shape functions, small-strain linear elastic, 2x2x2 particles per cell.
// Each is run with 1 thread and with all threads. A block with a velocity field that spins and
// shears it, so stresses are non-trivial. Run: build/release/bench/cairn_bench
#include <benchmark/benchmark.h>
#include <omp.h>

#include "cairn/sim/simulation.hpp"
#include "run_steps.hpp"

namespace cairn {
namespace {

template <int D>
Config bench_config(const std::string& shape, const std::string& model, int cells, int ppc) {
  Config c;
  c.simulation.dimension = D;
  c.simulation.mode = D == 2 ? Mode::plane_strain : Mode::three_d;
  c.simulation.end_time = 1.0;
  c.simulation.cfl = 0.4;
  c.grid.origin.assign(D, 0.0);
  c.grid.extent.assign(D, 1.0);
  c.grid.cell_size.assign(D, 1.0 / cells);
  c.method.shape = shape;
  MaterialConfig m;
  m.name = "solid";
  m.model = model;
  m.numbers = {{"density", 1000.0}, {"youngs_modulus", 1e7}, {"poissons_ratio", 0.3}};
  if (model == "neo_hookean") m.strings["form"] = "ln_j";
  c.materials.push_back(m);
  BodyConfig b;
  b.name = "block";
  b.material = "solid";
  b.shape.kind = "box";
  b.shape.min.assign(D, 0.2);
  b.shape.max.assign(D, 0.8);
  b.particles_per_cell.assign(D, ppc);
  b.velocity.assign(D, "0");
  b.velocity[0] = "0.5*(Y-0.5)";
  b.velocity[1] = "-0.5*(X-0.5)";
  c.bodies.push_back(b);
  return c;
}

using bench::run_steps;

void BM_Step2D_BSpline2_NeoHookean(benchmark::State& state) {
  run_steps<2>(state, bench_config<2>("bspline2", "neo_hookean", 160, 2));  // 36864 particles
}
void BM_Step3D_Linear_LinearElastic(benchmark::State& state) {
  run_steps<3>(state, bench_config<3>("linear", "linear_elastic", 40, 2));  // 110592 particles
}

BENCHMARK(BM_Step2D_BSpline2_NeoHookean)->Arg(1)->Arg(omp_get_num_procs())->UseRealTime()->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Step3D_Linear_LinearElastic)->Arg(1)->Arg(omp_get_num_procs())->UseRealTime()->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace cairn
