// Particles for axis-aligned boxes: fluid blocks on a lattice, and Akinci boundary layers for the
// domain container and for static boxes. (Meshes go through the Embree sampler instead.)
#pragma once
#include <vector>

#include "algorithms/vec3.hpp"

namespace mw {

// Fluid lattice filling [lo, hi]: points lo + (i + 1/2) r0, so a block touching a wall starts
// r0/2 from it. Throws InputError if the box is empty or inverted. In 2D `[lo, hi]` is a
// rectangle in the plane z = 0 (its z extent is ignored) and the lattice a square one in it.
std::vector<Vec3> fill_box_lattice(Vec3 lo, Vec3 hi, Real spacing, int dimensions = 3);

// Boundary particles lining a container [lo, hi]: the first layer `gap` outside the faces,
// further layers `spacing` apart beyond it. The gap matters: with a single Akinci layer, a fluid
// layer half a fluid spacing r0 from the wall has 55% too much density (cubic spline, h = 2 r0),
// one r0 away 6% too much, and 1.1 r0 away the rest density. Fluid blocks start r0/2 inside the
// faces, so the gap that lets them start at rest is rest_density_wall_gap() (wall_gap.hpp):
// 0.6 r0 for h = 2 r0 and one layer at r0/2, more for a wider kernel (from h = 1.5 r0 up), less
// for more layers.
// In 2D the container is the rectangle's outline in the plane z = 0 (its z extent is ignored).
std::vector<Vec3> sample_container_walls(Vec3 lo, Vec3 hi, Real spacing, int layers, Real gap, int dimensions = 3);

// Boundary particles of a solid static box [lo, hi]: the first layer on its faces, further layers
// `spacing` apart inside it. In 2D, on the rectangle's outline and inside it, in the plane z = 0.
std::vector<Vec3> sample_solid_box(Vec3 lo, Vec3 hi, Real spacing, int layers, int dimensions = 3);

}  // namespace mw
