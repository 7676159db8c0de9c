// A 2D object's outline (sampling/outline.hpp) to the three linked particle sets, as
// solid_sample.hpp does for a mesh: IBPs on the plane's lattice inside it (lattice.hpp's
// anchoring, one layer at z = 0, one-ring of 8), GPs at its corners with every edge split to
// at most r0, SBPs along its edges (one per GP edge at its middle, or as many as
// `surface_spacing` asks), each on its edge from corner 0 to corner 1 with corner 0 repeated
// (SbpLink::is_outline_edge) and the edge's outward in-plane normal.
#pragma once
#include <vector>

#include "sampling/solid_sample.hpp"

namespace mw {

struct OutlineSampleOptions {
    double surface_spacing = 1.0;    // × r0: the SBPs' spacing along the outline, at most
    double geometry_max_edge = 1.0;  // × r0: the GPs' edges, at most
};

// Throws InputError naming outline.source on a mesh that is not an outline or a spacing it
// cannot take. sample.geometry is the refined outline, its "triangles" (a, b, a) with the solid
// on the left of a → b.
SolidSample sample_outline(const TriangleMesh& outline, double spacing, double support_radius,
                           const OutlineSampleOptions& options = {});

// Per SBP: `depth`, or half the outline's thickness under it where that is less (the distance
// along -normal to the next edge), as surface_inset.hpp does in 3D. depth >= 0.
std::vector<double> outline_insets(const TriangleMesh& geometry, const SurfaceParticles& sbp, double depth);

}  // namespace mw
