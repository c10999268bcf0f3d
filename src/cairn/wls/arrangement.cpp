#include "cairn/wls/arrangement.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace cairn::wls {

bool radial_arrangement_supported(const std::string& kind) {
  return kind == "circle" || kind == "annulus" || kind == "sphere";
}

template <int D>
std::vector<Seed<D>> radial_arrangement(const BodyShapeConfig& shape, double spacing, bool surface) {
  if (!radial_arrangement_supported(shape.kind) || D == 1)
    throw std::invalid_argument("the radial arrangement needs a circle, annulus or sphere shape in 2D or 3D, not " +
                                std::string(D == 1 ? "a 1D body" : "a " + shape.kind));
  constexpr double pi = std::numbers::pi;
  Vec<D> c = Vec<D>::Zero();
  for (int a = 0; a < D && a < static_cast<int>(shape.center.size()); ++a) c[a] = shape.center[a];
  const double r_in = shape.kind == "annulus" ? shape.inner_radius : 0.0;
  const double r_out = shape.kind == "annulus" ? shape.outer_radius : shape.radius;
  std::vector<Seed<D>> seeds;
  // Points on a circle (2D) or sphere (3D) of radius r, about `spacing` apart, each with
  // `measure` (zero for surface points); `first` turns the circle so rings need not line up.
  auto ring = [&](double r, double measure_total, bool on_surface) {
    if constexpr (D == 2) {
      const int n = std::max(3, static_cast<int>(std::lround(2.0 * pi * r / spacing)));
      const double offset = on_surface ? 0.0 : 0.5;
      for (int j = 0; j < n; ++j) {
        const double t = 2.0 * pi * (j + offset) / n;
        seeds.push_back({Vec<D>(c + r * Vec<D>(std::cos(t), std::sin(t))), measure_total / n});
      }
    } else if constexpr (D == 3) {
      // Golden-spiral points: equal areas on the sphere (z uniform), longitudes turned by the
      // golden angle.
      const int n = std::max(4, static_cast<int>(std::lround(4.0 * pi * r * r / (spacing * spacing))));
      const double golden = pi * (3.0 - std::sqrt(5.0));
      for (int j = 0; j < n; ++j) {
        const double z = 1.0 - 2.0 * (j + 0.5) / n;
        const double s = std::sqrt(std::max(0.0, 1.0 - z * z));
        const double phi = golden * j;
        seeds.push_back({Vec<D>(c + r * Vec<D>(s * std::cos(phi), s * std::sin(phi), z)), measure_total / n});
      }
    }
  };
  const int n_r = std::max(1, static_cast<int>(std::lround((r_out - r_in) / spacing)));
  const double dr = (r_out - r_in) / n_r;
  for (int k = 0; k < n_r; ++k) {
    const double lo = r_in + k * dr, hi = lo + dr;
    const double measure = D == 2 ? pi * (hi * hi - lo * lo) : 4.0 / 3.0 * pi * (hi * hi * hi - lo * lo * lo);
    ring(lo + 0.5 * dr, measure, false);
  }
  if (surface) {
    ring(r_out, 0.0, true);
    if (r_in > 0.0) ring(r_in, 0.0, true);
  }
  return seeds;
}

template <int D>
std::vector<Vec<D>> lattice_surface_points(const std::function<bool(const Vec<D>&)>& inside,
                                           const Vec<D>& first, const Vec<D>& spacing,
                                           const IVec<D>& count) {
  long long total = 1;
  for (int a = 0; a < D; ++a) total *= count[a];
  std::vector<Vec<D>> points;
  for (long long k = 0; k < total; ++k) {
    long long rem = k;
    IVec<D> i;
    for (int a = 0; a < D; ++a) {
      i[a] = static_cast<int>(rem % count[a]);
      rem /= count[a];
    }
    const Vec<D> X = first + i.template cast<double>().cwiseProduct(spacing);
    if (!inside(X)) continue;
    for (int a = 0; a < D; ++a)
      for (int side : {-1, 1}) {
        const int j = i[a] + side;
        if (j < 0 || j >= count[a]) continue;
        Vec<D> out = X;
        out[a] += side * spacing[a];
        if (inside(out)) continue;
        Vec<D> in = X;
        for (int it = 0; it < 60 && std::abs(out[a] - in[a]) > 1e-12 * spacing[a]; ++it) {
          Vec<D> mid = 0.5 * (in + out);
          (inside(mid) ? in : out) = mid;
        }
        points.push_back(0.5 * (in + out));
      }
  }
  return points;
}

template std::vector<Seed<1>> radial_arrangement<1>(const BodyShapeConfig&, double, bool);
template std::vector<Seed<2>> radial_arrangement<2>(const BodyShapeConfig&, double, bool);
template std::vector<Seed<3>> radial_arrangement<3>(const BodyShapeConfig&, double, bool);
template std::vector<Vec<1>> lattice_surface_points<1>(const std::function<bool(const Vec<1>&)>&, const Vec<1>&,
                                                       const Vec<1>&, const IVec<1>&);
template std::vector<Vec<2>> lattice_surface_points<2>(const std::function<bool(const Vec<2>&)>&, const Vec<2>&,
                                                       const Vec<2>&, const IVec<2>&);
template std::vector<Vec<3>> lattice_surface_points<3>(const std::function<bool(const Vec<3>&)>&, const Vec<3>&,
                                                       const Vec<3>&, const IVec<3>&);

}  // namespace cairn::wls
