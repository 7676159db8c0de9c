// The signed distance to a 2D outline (sampling/outline.hpp) on a grid in its plane: what the
// velocity-position correction reads to keep fluid and moving solids out of a static object in a
// 2D scene, as signed_distance_grid (sampling/signed_distance.hpp) gives it for a 3D mesh.
#pragma once

#include <cstddef>

#include "sampling/mesh.hpp"
#include "sampling/signed_distance.hpp"

namespace mw {

// The grid covers the outline's bounding box in x and y grown by `band` plus two nodes on every
// side, at `spacing` (or, past `max_nodes` nodes, 0: no limit, else at least 8, the smallest
// spacing that fits), with two layers of nodes, half a spacing either side of the plane z = 0,
// that hold the same distances: interpolated across them (algorithms/distance_field.hpp) the field
// is the plane's. Distances are exact, to the outline's edges that are not sealed (an edge along
// the floor, say), negative inside its loops (even-odd); exit_triangles counts those edges, and
// when every edge is sealed no grid is built.
SignedDistanceGrid signed_distance_outline(const TriangleMesh& outline, double spacing, double band,
                                           std::size_t max_nodes, const SealedFace& sealed = nullptr);

}  // namespace mw
