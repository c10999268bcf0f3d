// Particle placements that the WLS method needs (seed 001 Sec. 3.3, Fig. 4):
//  - surface particles (flag beta_p = 1, Eq. 13): zero-volume, zero-mass sample points on the
//    body's surface. For lattice (Cartesian) bodies they are placed where the segment between a
//    lattice point inside the body and an axis neighbour outside it crosses the surface (found by
//    bisection on the body's inside test, so the same code serves every shape kind, pictures
//    included: for a picture the crossing is the pixel edge, "halfway between samples that are in
//    and out" of Sec. 3.3 made exact);
//  - the body-fitted radial arrangement of Fig. 4b for circles, annuli and spheres: concentric
//    rings (2D) or shells (3D) of interior particles, each carrying the area/volume of its piece of
//    the ring or shell, plus one ring/shell of surface particles on each bounding circle/sphere.
// A particle is a surface particle exactly when its initial volume is zero (wls::is_surface).
#pragma once

#include <functional>
#include <vector>

#include "cairn/config/config.hpp"
#include "cairn/math/types.hpp"

namespace cairn::wls {

/// One particle to create: reference position and measure (area in 2D, volume in 3D; 0 for a
/// surface particle).
template <int D>
struct Seed {
  Vec<D> X = Vec<D>::Zero();
  double measure = 0.0;
};

/// Whether `kind` can take the radial arrangement (circle, annulus, sphere).
bool radial_arrangement_supported(const std::string& kind);

/// Radial arrangement of a circle/annulus (2D) or sphere/spherical shell (3D) with particle
/// spacing about `spacing` along the radius and the circumference; surface rings/shells are added
/// when `surface` is set. Throws std::invalid_argument for other shape kinds or D = 1.
template <int D>
std::vector<Seed<D>> radial_arrangement(const BodyShapeConfig& shape, double spacing, bool surface);

/// Surface points of the body `inside` sampled on the lattice first + i .* spacing,
/// 0 <= i < count: one point per pair of axis neighbours of which exactly the first is inside,
/// on the surface between them (bisection to 1e-12 of the spacing). Pairs leaving the lattice
/// (the grid faces) give no point.
template <int D>
std::vector<Vec<D>> lattice_surface_points(const std::function<bool(const Vec<D>&)>& inside,
                                           const Vec<D>& first, const Vec<D>& spacing,
                                           const IVec<D>& count);

}  // namespace cairn::wls
