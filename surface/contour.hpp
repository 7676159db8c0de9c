// The fluid's surface in 2D: the colour field's iso-line on a plane of nodes (z = 0) by marching
// squares, as an outline (edges (a, b, a), sampling/outline.hpp) with the fluid on the left of
// each edge, so that the frame writers, the preview and a reader of the OBJ frames take it as they
// take a 2D object's outline. Host only, at frame times (docs/surface.md).
#pragma once
#include <vector>

#include "sampling/mesh.hpp"
#include "simulation/simulation.hpp"

namespace mw {

// The level set c = iso of the colour field `color` at `nodes` (one plane: nodes.dims[2] == 1;
// c above iso is fluid). A cell whose diagonal corners are fluid and the others not joins the
// fluid corners when the mean of its four values is above iso. Edge points shared by two cells
// are one vertex, so each closed curve is a closed loop of edges.
TriangleMesh contour_color_field(const SurfaceNodes& nodes, const std::vector<Real>& color, double iso);

}  // namespace mw
