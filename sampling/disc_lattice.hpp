// One layer of a fluid emitter (algorithms/emitter.hpp): points on a square lattice at the fluid's
// spacing over a disc, so that layers released r0 apart fill the stream at rest spacing.
#pragma once
#include <vector>

#include "algorithms/vec3.hpp"

namespace mw {

// The lattice points i s u + j s w (integers i, j; s = spacing) within `radius` of the origin, u
// and w a basis of the plane perpendicular to `normal` (unit); the origin is always one, so a disc
// narrower than the spacing holds one point. Ordered by j, then i. In 2D (`normal` in the plane
// z = 0) the disc is a segment across the normal in that plane: the points i s u alone, u = ẑ × n.
std::vector<Vec3> disc_lattice(Vec3 normal, Real radius, Real spacing, int dimensions = 3);

}  // namespace mw
