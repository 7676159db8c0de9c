#include "sampling/sheet_sample.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "common/errors.hpp"
#include "sampling/mesh_refinement.hpp"

namespace mw {

SheetSample sample_sheet(const TriangleMesh& input, double spacing) {
    const std::string src = input.source.empty() ? std::string("mesh") : input.source;
    if (!std::isfinite(spacing) || spacing <= 0) throw InputError(src + ": spacing r0 must be positive");
    validate_mesh(input, false);
    const TriangleMesh mesh = without_unused_vertices(input);
    const EdgeReport edges = edge_report(mesh);
    if (edges.nonmanifold_edges > 0)
        throw InputError(src + ": a cloth is a manifold sheet, but " + std::to_string(edges.nonmanifold_edges) +
                         " edge(s) are shared by more than two triangles");
    if (edges.boundary_edges == 0)
        throw InputError(src + ": the mesh is closed, and a cloth is an open sheet (a closed surface is a volume: give "
                               "it kind \"elastic\")");
    if (!edges.consistently_oriented())
        throw InputError(src + ": the sheet is not consistently oriented (" + std::to_string(edges.misoriented_edges) +
                         " edge(s) are traversed the same way by both their triangles)");
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
        if (!(triangle_area(mesh, t) > 0))
            throw InputError(src + ": triangle " + std::to_string(t + 1) + " has no area");
    SheetSample out;
    out.boundary_edges = edges.boundary_edges;
    // A square grid at spacing r0 keeps its vertices (its diagonals are √2 r0): nodes about r0 apart.
    out.mesh = refine_long_edges(mesh, kSheetMaxEdge * spacing).mesh;
    const std::size_t n = out.mesh.vertices.size();
    out.node_area.assign(n, 0.0);
    std::vector<std::vector<std::uint32_t>> neighbours(n);
    for (std::size_t t = 0; t < out.mesh.triangles.size(); ++t) {
        const double third = triangle_area(out.mesh, t) / 3;
        const auto& tri = out.mesh.triangles[t];
        for (int k = 0; k < 3; ++k) {
            const auto a = std::uint32_t(tri[k]), b = std::uint32_t(tri[(k + 1) % 3]);
            out.node_area[a] += third;
            neighbours[a].push_back(b);
            neighbours[b].push_back(a);
        }
    }
    out.graph_offsets.assign(1, 0);
    for (auto& list : neighbours) {
        std::sort(list.begin(), list.end());
        list.erase(std::unique(list.begin(), list.end()), list.end());
        out.graph_links.insert(out.graph_links.end(), list.begin(), list.end());
        out.graph_offsets.push_back(std::uint32_t(out.graph_links.size()));
    }
    // One layer: no candidate is dropped for facing the other way (there is no other side).
    SurfaceOptions options;
    options.two_sided = false;
    out.sbp = sample_surface(out.mesh, spacing, options);
    return out;
}

}  // namespace mw
