#include "sampling/outline_distance.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "sampling/outline.hpp"

namespace mw {

namespace {

// Nodes along x and y covering [lo - margin, hi + margin] at `spacing`, centred on the box; two
// along z, at -spacing/2 and +spacing/2.
LatticeGrid covering_plane_grid(const Aabb& box, double spacing, double margin) {
    LatticeGrid g;
    g.spacing = spacing;
    for (int a = 0; a < 2; ++a) {
        const double length = box.extent()[a] + 2 * margin;
        g.dims[a] = std::max(2, static_cast<int>(std::ceil(length / spacing - 1e-9)) + 1);
        g.origin[a] = box.center()[a] - 0.5 * (g.dims[a] - 1) * spacing;
    }
    g.dims[2] = 2;
    g.origin[2] = -0.5 * spacing;
    return g;
}

}  // namespace

SignedDistanceGrid signed_distance_outline(const TriangleMesh& outline, double spacing, double band,
                                           std::size_t max_nodes, const SealedFace& sealed) {
    const auto start = std::chrono::steady_clock::now();
    if (!(spacing > 0) || !(band >= 0) || (max_nodes > 0 && max_nodes < 8))
        throw std::invalid_argument("signed_distance_outline: needs spacing > 0, band >= 0 and max_nodes 0 or >= 8");
    const std::vector<std::array<int, 2>> edges = outline_edges(outline);
    std::vector<std::array<int, 2>> exits;
    for (const auto& e : edges) {
        const Vec3d& a = outline.vertices[std::size_t(e[0])];
        const Vec3d& b = outline.vertices[std::size_t(e[1])];
        if (!sealed || !sealed(a, b, a)) exits.push_back(e);
    }
    SignedDistanceGrid result;
    result.exit_triangles = exits.size();
    if (exits.empty()) return result;

    const Aabb box = bounding_box(outline);
    result.grid = covering_plane_grid(box, spacing, band + 2 * spacing);
    if (max_nodes > 0 && result.grid.count() > max_nodes) {
        // The smallest spacing whose grid fits: the extents over the node budget's square root
        // (two layers), then grown until the +1 nodes per axis fit too.
        const double ex = box.extent().x() + 2 * band + 4 * spacing, ey = box.extent().y() + 2 * band + 4 * spacing;
        double coarse = std::max(spacing, std::sqrt(ex * ey / (0.5 * double(max_nodes))));
        while ((result.grid = covering_plane_grid(box, coarse, band + 2 * coarse)).count() > max_nodes) coarse *= 1.01;
    }
    const LatticeGrid& grid = result.grid;
    const std::size_t nx = std::size_t(grid.dims[0]), ny = std::size_t(grid.dims[1]), layer = nx * ny;
    result.distance.resize(grid.count());
#pragma omp parallel for schedule(static)
    for (long id = 0; id < static_cast<long>(layer); ++id) {
        const std::size_t u = std::size_t(id);
        Vec3d p = grid.position(int(u % nx), int(u / nx), 0);
        p.z() = 0;  // measured in the plane; both layers take the value
        // An edge (a, b) is the degenerate triangle (a, b, a): the distance to its segment.
        double d = std::numeric_limits<double>::infinity();
        for (const auto& e : exits) {
            const Vec3d& a = outline.vertices[std::size_t(e[0])];
            d = std::min(d, point_triangle_distance(p, a, outline.vertices[std::size_t(e[1])], a));
        }
        const double signed_d = inside_loops(outline.vertices, edges, p.x(), p.y()) ? -d : d;
        result.distance[u] = signed_d;
        result.distance[u + layer] = signed_d;
    }
    result.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return result;
}

}  // namespace mw
