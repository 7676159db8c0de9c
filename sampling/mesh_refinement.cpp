#include "sampling/mesh_refinement.hpp"

#include <Eigen/LU>
#include <cstdint>
#include <sstream>
#include <unordered_map>

#include "common/errors.hpp"

namespace mw {

namespace {

std::uint64_t edge_key(int a, int b) {
    if (a > b) std::swap(a, b);
    return (std::uint64_t(std::uint32_t(a)) << 32) | std::uint32_t(b);
}

// The corners of the parent in its own barycentric coordinates, and its edges' midpoints.
const Vec3d kCorner[3] = {Vec3d(1, 0, 0), Vec3d(0, 1, 0), Vec3d(0, 0, 1)};
Vec3d midpoint_of(int a, int b) { return 0.5 * (kCorner[a] + kCorner[b]); }

}  // namespace

void RefinedMesh::locate(int& triangle, Vec3d& bary) const {
    for (const Split& split : passes) {
        const int begin = split.first_child[std::size_t(triangle)], end = split.first_child[std::size_t(triangle) + 1];
        // The child whose weights for the point are the least negative: the one that holds it
        // (points on a shared edge are held by both; either gives the same position).
        int best = begin;
        Vec3d best_bary = bary;
        double best_min = -1e300;
        for (int c = begin; c < end; ++c) {
            const auto& k = split.child_corners[std::size_t(c)];
            Eigen::Matrix3d corners;
            corners << k[0], k[1], k[2];
            const Vec3d weights = corners.inverse() * bary;
            if (weights.minCoeff() > best_min) best_min = weights.minCoeff(), best = c, best_bary = weights;
        }
        triangle = best;
        bary = best_bary;
    }
}

RefinedMesh refine_long_edges(const TriangleMesh& input, double max_edge, std::size_t max_triangles) {
    const std::string src = input.source.empty() ? std::string("mesh") : input.source;
    if (!(max_edge > 0)) throw InputError(src + ": the longest edge allowed must be positive");
    RefinedMesh out;
    out.mesh = input;
    TriangleMesh& mesh = out.mesh;
    const double limit2 = max_edge * max_edge;
    auto too_long = [&](int a, int b) {
        return (mesh.vertices[std::size_t(a)] - mesh.vertices[std::size_t(b)]).squaredNorm() > limit2;
    };
    // Midpoints made so far, by edge: shared by the two triangles of an edge, over all passes.
    std::unordered_map<std::uint64_t, int> midpoints;
    for (;;) {
        // This pass's split edges, and their midpoints.
        bool any = false;
        for (const auto& t : mesh.triangles)
            for (int e = 0; e < 3; ++e) {
                const int a = t[e], b = t[(e + 1) % 3];
                if (!too_long(a, b) || midpoints.count(edge_key(a, b))) continue;
                midpoints.emplace(edge_key(a, b), int(mesh.vertices.size()));
                mesh.vertices.push_back(0.5 * (mesh.vertices[std::size_t(a)] + mesh.vertices[std::size_t(b)]));
                any = true;
            }
        if (!any) break;

        RefinedMesh::Split split;
        split.first_child.reserve(mesh.triangles.size() + 1);
        std::vector<std::array<int, 3>> next;
        auto add = [&](std::array<int, 3> vertices, std::array<Vec3d, 3> corners) {
            next.push_back(vertices);
            split.child_corners.push_back(corners);
        };
        for (const auto& t : mesh.triangles) {
            split.first_child.push_back(int(next.size()));
            int mid[3];  // mid[e]: the midpoint of edge e (t[e], t[e + 1]), or -1
            int splits = 0;
            for (int e = 0; e < 3; ++e) {
                const auto it = midpoints.find(edge_key(t[e], t[(e + 1) % 3]));
                mid[e] = it == midpoints.end() ? -1 : it->second;
                splits += mid[e] >= 0;
            }
            if (splits == 0) {
                add(t, {kCorner[0], kCorner[1], kCorner[2]});
            } else if (splits == 3) {
                add({t[0], mid[0], mid[2]}, {kCorner[0], midpoint_of(0, 1), midpoint_of(2, 0)});
                add({mid[0], t[1], mid[1]}, {midpoint_of(0, 1), kCorner[1], midpoint_of(1, 2)});
                add({mid[2], mid[1], t[2]}, {midpoint_of(2, 0), midpoint_of(1, 2), kCorner[2]});
                add({mid[0], mid[1], mid[2]}, {midpoint_of(0, 1), midpoint_of(1, 2), midpoint_of(2, 0)});
            } else if (splits == 1) {
                // Corners renamed so that the split edge is (a, b) and c is opposite it; the
                // children keep the parent's winding.
                const int e = mid[0] >= 0 ? 0 : mid[1] >= 0 ? 1 : 2;
                const int a = e, b = (e + 1) % 3, c = (e + 2) % 3;
                add({t[a], mid[e], t[c]}, {kCorner[a], midpoint_of(a, b), kCorner[c]});
                add({mid[e], t[b], t[c]}, {midpoint_of(a, b), kCorner[b], kCorner[c]});
            } else {
                // Two split edges, (a, b) and (b, c): the corner triangle at b, and the quad
                // (a, m_ab, m_bc, c) cut along its shorter diagonal.
                const int kept = mid[0] < 0 ? 0 : mid[1] < 0 ? 1 : 2;  // the edge not split: (c, a)
                const int c = kept, a = (kept + 1) % 3, b = (kept + 2) % 3;
                const int m_ab = mid[a], m_bc = mid[b];
                add({m_ab, t[b], m_bc}, {midpoint_of(a, b), kCorner[b], midpoint_of(b, c)});
                const double d_a = (mesh.vertices[std::size_t(t[a])] - mesh.vertices[std::size_t(m_bc)]).squaredNorm();
                const double d_c = (mesh.vertices[std::size_t(t[c])] - mesh.vertices[std::size_t(m_ab)]).squaredNorm();
                if (d_a <= d_c) {
                    add({t[a], m_ab, m_bc}, {kCorner[a], midpoint_of(a, b), midpoint_of(b, c)});
                    add({t[a], m_bc, t[c]}, {kCorner[a], midpoint_of(b, c), kCorner[c]});
                } else {
                    add({t[a], m_ab, t[c]}, {kCorner[a], midpoint_of(a, b), kCorner[c]});
                    add({m_ab, m_bc, t[c]}, {midpoint_of(a, b), midpoint_of(b, c), kCorner[c]});
                }
            }
            if (next.size() > max_triangles) {
                std::ostringstream s;
                s << src << ": refining the mesh for its geometry particles (no edge longer than " << max_edge
                  << ") takes more than " << max_triangles
                  << " triangles; use a finer mesh, a coarser fluid.spacing, or a smaller object";
                throw InputError(s.str());
            }
        }
        split.first_child.push_back(int(next.size()));
        mesh.triangles = std::move(next);
        out.passes.push_back(std::move(split));
    }
    return out;
}

}  // namespace mw
