// cairn_shape_probe: evaluates a registered shape family on particles read from stdin, through the
// same ShapeFamily::build the simulations use. Used by verification/node_force_integration (grid
// sums of seed 003 Eq. 42 for arbitrary, non-lattice particle positions) and by
// docs/plot_shape_functions.py (plots of the 1D bases).
//
//   cairn_shape_probe --family NAME --dim D --cells N [N N] --h H [H H] --origin O [O O]
//                     [--periodic 0|1 ...] [--smoothing L] [--cpdi-max-span S]
//                     [--mode stencils|node-sums]
//
// stdin, one particle per line: x (D numbers), l_p0 (D), V_p, and optionally F (D x D, row-major).
// stdout:
//   stencils   one line per particle and stencil slot: p, dof position (D), S_pi, G_pi (D)
//   node-sums  one line per node touched: dof position (D), sum_p S_pi V_p, sum_p G_pi V_p (D)
#include <cstdio>
#include <iostream>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include "cairn/shapes/shape_family.hpp"
#include "cairn/transfer/transfer.hpp"

namespace cairn {
namespace {

struct Options {
  std::string family = "ugimp", mode = "stencils";
  int dim = 1;
  std::vector<int> cells;
  std::vector<double> h, origin;
  std::vector<int> periodic;
  double smoothing = 0.0, max_span = 2.0;
};

template <int D>
int run(const Options& o) {
  Config cfg;
  cfg.method.shape = o.family;
  cfg.method.plugin.set("smoothing_length", o.smoothing);
  cfg.method.plugin.set("cpdi_max_span", o.max_span);
  auto fam = make_shape_family<D>(ShapeContext{cfg.method, D});
  Vec<D> origin, h;
  IVec<D> n;
  std::array<bool, D> per{};
  for (int a = 0; a < D; ++a) {
    origin[a] = o.origin.at(a);
    h[a] = o.h.at(a);
    n[a] = o.cells.at(a);
    per[a] = a < static_cast<int>(o.periodic.size()) && o.periodic[a] != 0;
  }
  const Grid<D> grid(origin, n, h, fam->ghost_layers(), per);
  Particles<D> parts;
  std::vector<double> volume;
  std::string line;
  while (std::getline(std::cin, line)) {
    std::istringstream in(line);
    std::vector<double> v;
    double x;
    while (in >> x) v.push_back(x);
    if (v.empty()) continue;
    if (v.size() != static_cast<std::size_t>(2 * D + 1) && v.size() != static_cast<std::size_t>(2 * D + 1 + D * D)) {
      std::cerr << "cairn_shape_probe: expected " << 2 * D + 1 << " or " << 2 * D + 1 + D * D
                << " numbers per particle, found " << v.size() << ": " << line << "\n";
      return 2;
    }
    Vec<D> pos, size;
    for (int a = 0; a < D; ++a) {
      pos[a] = v[a];
      size[a] = v[D + a];
    }
    parts.add(pos, Vec<D>::Zero(), 1.0, v[2 * D], size, 0, 0);
    volume.push_back(v[2 * D]);
    if (v.size() > static_cast<std::size_t>(2 * D + 1))
      for (int a = 0; a < D; ++a)
        for (int b = 0; b < D; ++b) parts.deformation_gradient.back()(a, b) = v[2 * D + 1 + a * D + b];
  }
  TransferCache<D> cache;
  fam->build(grid, parts, cache);
  std::map<std::int32_t, std::pair<double, Vec<D>>> sums;
  for (std::size_t p = 0; p < parts.n(); ++p) {
    // Every entry of p's stencil, whatever the cache's layout (list or per-axis tensor factors).
    for_each_entry(cache, p, [&](std::int32_t node, double S, const Vec<D>& G) {
      if (o.mode == "stencils") {
        const Vec<D> x = fam->dof_position(grid, node);
        std::printf("%zu", p);
        for (int a = 0; a < D; ++a) std::printf(" %.17g", x[a]);
        std::printf(" %.17g", S);
        for (int a = 0; a < D; ++a) std::printf(" %.17g", G[a]);
        std::printf("\n");
      } else {
        auto& e = sums.try_emplace(node, 0.0, Vec<D>::Zero()).first->second;
        e.first += S * volume[p];
        e.second += G * volume[p];
      }
    });
  }
  for (const auto& [node, e] : sums) {
    const Vec<D> x = fam->dof_position(grid, node);
    for (int a = 0; a < D; ++a) std::printf("%.17g ", x[a]);
    std::printf("%.17g", e.first);
    for (int a = 0; a < D; ++a) std::printf(" %.17g", e.second[a]);
    std::printf("\n");
  }
  return 0;
}

}  // namespace
}  // namespace cairn

int main(int argc, char** argv) {
  cairn::Options o;
  auto numbers = [&](int& i, auto& out) {
    while (i + 1 < argc && argv[i + 1][0] != '-') out.push_back(std::stod(argv[++i]));
  };
  try {
    for (int i = 1; i < argc; ++i) {
      const std::string a = argv[i];
      auto next = [&]() -> std::string {
        if (i + 1 >= argc) throw std::invalid_argument(a + " needs a value");
        return argv[++i];
      };
      if (a == "--family") o.family = next();
      else if (a == "--mode") o.mode = next();
      else if (a == "--dim") o.dim = std::stoi(next());
      else if (a == "--smoothing") o.smoothing = std::stod(next());
      else if (a == "--cpdi-max-span") o.max_span = std::stod(next());
      else if (a == "--cells") { std::vector<double> v; numbers(i, v); for (double x : v) o.cells.push_back(static_cast<int>(x)); }
      else if (a == "--h") numbers(i, o.h);
      else if (a == "--origin") {
        // origins may be negative: take the next `dim` arguments verbatim
        for (int k = 0; k < o.dim && i + 1 < argc; ++k) o.origin.push_back(std::stod(argv[++i]));
      }
      else if (a == "--periodic") { std::vector<double> v; numbers(i, v); for (double x : v) o.periodic.push_back(static_cast<int>(x)); }
      else throw std::invalid_argument("unknown option " + a);
    }
    if (o.mode != "stencils" && o.mode != "node-sums") throw std::invalid_argument("--mode stencils|node-sums");
    if (static_cast<int>(o.cells.size()) < o.dim || static_cast<int>(o.h.size()) < o.dim ||
        static_cast<int>(o.origin.size()) < o.dim)
      throw std::invalid_argument("--cells, --h and --origin need one value per axis (give --dim first)");
    switch (o.dim) {
      case 1: return cairn::run<1>(o);
      case 2: return cairn::run<2>(o);
      case 3: return cairn::run<3>(o);
      default: throw std::invalid_argument("--dim must be 1, 2 or 3");
    }
  } catch (const std::exception& e) {
    std::cerr << "cairn_shape_probe: " << e.what() << "\n";
    return 2;
  }
}
