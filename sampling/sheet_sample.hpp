// A cloth's sheet mesh to particles (docs/cloth.md): one layer. The mesh is refined until no edge
// is longer than 1.5 r0; its vertices are the shape-matching nodes (each with its share of the area,
// and its neighbours along the edges, which the regions grow on), and the surface particles the
// fluid meets are sampled on its triangles as on any surface (surface_sampler.hpp). Host only.
#pragma once
#include <cstdint>
#include <vector>

#include "sampling/mesh.hpp"
#include "sampling/surface_sampler.hpp"

namespace mw {

constexpr double kSheetMaxEdge = 1.5;  // × r0

struct SheetSample {
    TriangleMesh mesh;               // refined: no edge longer than kSheetMaxEdge r0; its vertices are the nodes
    std::vector<double> node_area;   // per vertex: a third of the area of each triangle it is a corner of
    std::vector<std::uint32_t> graph_offsets, graph_links;  // per vertex, its neighbours along edges (CSR)
    SurfaceParticles sbp;            // on `mesh`'s triangles
    std::size_t boundary_edges = 0;  // of the input mesh
};

// Refuses (InputError naming the mesh) a mesh that is not an open, manifold, consistently oriented
// sheet: a closed surface is a volume (an elastic object), an edge of three triangles is no sheet.
SheetSample sample_sheet(const TriangleMesh& mesh, double spacing);

}  // namespace mw
