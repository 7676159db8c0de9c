#include "surface/contour.hpp"

#include <array>
#include <cstdint>
#include <stdexcept>

namespace mw {

namespace {

// A cell's corners 0 (i, j), 1 (i+1, j), 2 (i+1, j+1), 3 (i, j+1) and edges 0 (corners 0-1),
// 1 (1-2), 2 (3-2), 3 (0-3). Per case (bit k: corner k is fluid), the pairs of edges the iso-line
// crosses; the saddles (5, 10) by whether the cell's centre is fluid.
struct CellSegments {
    int count;
    std::array<std::array<int, 2>, 2> edges;
};

CellSegments segments_of(int index, bool centre_fluid) {
    switch (index) {
        case 1: case 14: return {1, {{{3, 0}}}};
        case 2: case 13: return {1, {{{0, 1}}}};
        case 3: case 12: return {1, {{{3, 1}}}};
        case 4: case 11: return {1, {{{1, 2}}}};
        case 6: case 9: return {1, {{{0, 2}}}};
        case 7: case 8: return {1, {{{3, 2}}}};
        // Corners 0 and 2 fluid: joined through the centre, the line cuts off corners 1 and 3.
        case 5: return centre_fluid ? CellSegments{2, {{{0, 1}, {2, 3}}}} : CellSegments{2, {{{3, 0}, {1, 2}}}};
        // Corners 1 and 3 fluid: joined through the centre, the line cuts off corners 0 and 2.
        case 10: return centre_fluid ? CellSegments{2, {{{3, 0}, {1, 2}}}} : CellSegments{2, {{{0, 1}, {2, 3}}}};
        default: return {0, {}};
    }
}

}  // namespace

TriangleMesh contour_color_field(const SurfaceNodes& nodes, const std::vector<Real>& color, double iso) {
    TriangleMesh mesh;
    mesh.source = "the fluid's surface";
    if (nodes.count() == 0) return mesh;
    if (nodes.dims[2] != 1) throw std::logic_error("contour_color_field: the nodes are not one plane");
    if (color.size() != nodes.count()) throw std::logic_error("contour_color_field: field and nodes differ in size");
    const int nx = nodes.dims[0], ny = nodes.dims[1];
    const double h = double(nodes.spacing), x0 = double(nodes.origin.x), y0 = double(nodes.origin.y);
    const auto value = [&](int i, int j) { return double(color[std::size_t(j) * std::size_t(nx) + std::size_t(i)]); };
    // The vertex on each crossed edge of the node lattice, made once: edge 2 n (+x from node n) and
    // 2 n + 1 (+y from node n).
    std::vector<int> vertex_of_edge(2 * nodes.count(), -1);
    const auto vertex = [&](int i, int j, bool along_y) {
        const std::size_t key = 2 * (std::size_t(j) * std::size_t(nx) + std::size_t(i)) + (along_y ? 1 : 0);
        if (vertex_of_edge[key] < 0) {
            const double a = value(i, j), b = along_y ? value(i, j + 1) : value(i + 1, j);
            const double t = (iso - a) / (b - a);
            vertex_of_edge[key] = int(mesh.vertices.size());
            mesh.vertices.emplace_back(x0 + h * (i + (along_y ? 0.0 : t)), y0 + h * (j + (along_y ? t : 0.0)), 0.0);
        }
        return vertex_of_edge[key];
    };
    for (int j = 0; j + 1 < ny; ++j)
        for (int i = 0; i + 1 < nx; ++i) {
            const double v[4] = {value(i, j), value(i + 1, j), value(i + 1, j + 1), value(i, j + 1)};
            int index = 0;
            for (int k = 0; k < 4; ++k) index |= (v[k] > iso ? 1 : 0) << k;
            if (index == 0 || index == 15) continue;
            const CellSegments cell = segments_of(index, 0.25 * (v[0] + v[1] + v[2] + v[3]) > iso);
            for (int s = 0; s < cell.count; ++s) {
                int ends[2];
                for (int e = 0; e < 2; ++e) {
                    switch (cell.edges[s][e]) {
                        case 0: ends[e] = vertex(i, j, false); break;
                        case 1: ends[e] = vertex(i + 1, j, true); break;
                        case 2: ends[e] = vertex(i, j + 1, false); break;
                        default: ends[e] = vertex(i, j, true); break;
                    }
                }
                const Vec3d& a = mesh.vertices[std::size_t(ends[0])];
                const Vec3d& b = mesh.vertices[std::size_t(ends[1])];
                if (a == b) continue;  // both ends on a node whose value is iso exactly
                // Fluid on the left: the field rises into the fluid, so the edge's left normal
                // points along the field's (bilinear) gradient at the edge's middle.
                const double tx = (0.5 * (a.x() + b.x()) - x0) / h - i, ty = (0.5 * (a.y() + b.y()) - y0) / h - j;
                const double gx = (1 - ty) * (v[1] - v[0]) + ty * (v[2] - v[3]);
                const double gy = (1 - tx) * (v[3] - v[0]) + tx * (v[2] - v[1]);
                const double left = -(b.y() - a.y()) * gx + (b.x() - a.x()) * gy;
                if (left >= 0) mesh.triangles.push_back({ends[0], ends[1], ends[0]});
                else mesh.triangles.push_back({ends[1], ends[0], ends[1]});
            }
        }
    return mesh;
}

}  // namespace mw
