// How close fluid may start to a solid: the clearance set-up keeps between a fluid lattice and
// the boundary particles of static boxes and objects (the domain walls keep theirs through
// their gap outside the faces, wall_gap.hpp).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "algorithms/vec3.hpp"

namespace mw {

// Fluid particles closer than this many r0 to a particle of a static box or an object are left
// out. A fluid layer r0/2 from an Akinci layer starts 55% over-dense and PCISPH blows it apart in
// the first step; at r0 it is 6% over-dense, which the first step corrects quietly
// (docs/solver.md, "Boundaries").
constexpr double kFluidClearance = 1.0;

// The closest a fluid particle kept by that rule can start to a static box's face, whose first
// layer is sampled on a square grid of `boundary_spacing`: above the middle of a grid square, its
// nearest boundary particle is boundary_spacing/√2 to the side (0.935 r0 for the defaults).
inline Real carved_face_distance(Real clearance, Real boundary_spacing) {
    const double c = clearance, s = boundary_spacing;
    return Real(std::sqrt(std::max(0.0, c * c - s * s / 2)));
}

// For each point of `fluid`, whether a solid occupies it: it lies inside one of `boxes` (static
// boxes are sampled on their faces only, so a large one is hollow and its inside has no particle
// to keep fluid away), or closer than `clearance` to one of `solid_points`. A point exactly
// `clearance` away is kept, whichever way float rounding leans, so a symmetric scene is carved
// symmetrically.
std::vector<std::uint8_t> points_solids_occupy(const std::vector<Vec3>& fluid, const std::vector<Vec3>& solid_points,
                                               const std::vector<Eigen::AlignedBox3d>& boxes, Real clearance);

}  // namespace mw
