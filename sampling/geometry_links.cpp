#include "sampling/geometry_links.hpp"

#include "sampling/first_exception.hpp"

#include <algorithm>

#include "sampling/kdtree.hpp"

namespace mw {

GeometryLinks link_geometry(const TriangleMesh& mesh, const std::vector<Vec3d>& ibp_positions, double h) {
    GeometryLinks out;
    out.positions = mesh.vertices;
    const long n = static_cast<long>(mesh.vertices.size());
    out.offsets.assign(static_cast<std::size_t>(n) + 1, 0);
    if (ibp_positions.empty()) {
        out.without_ibp_in_h = static_cast<std::size_t>(n);
        return out;
    }
    PointTree tree(ibp_positions);
    std::vector<std::vector<std::pair<std::uint32_t, double>>> found(static_cast<std::size_t>(n));
    std::size_t orphans = 0;
    FirstException failure;  // the neighbour lists allocate: out of memory must reach the caller
#pragma omp parallel for schedule(dynamic, 256) reduction(+ : orphans)
    for (long g = 0; g < n; ++g) {
        bool orphan = false;
        failure.run([&] {
            auto& list = found[static_cast<std::size_t>(g)];
            const Vec3d& x = mesh.vertices[static_cast<std::size_t>(g)];
            tree.within(x, h, list);
            // Keep only strictly positive weights (r < h), sorted by IBP index.
            list.erase(std::remove_if(list.begin(), list.end(), [&](const auto& e) { return e.second >= h * h; }), list.end());
            std::sort(list.begin(), list.end());
            if (list.empty()) {
                const auto nearest = tree.nearest(x);
                list.push_back({static_cast<std::uint32_t>(nearest.first), -1.0});  // marker: weight 1
                orphan = true;
            }
            out.offsets[static_cast<std::size_t>(g) + 1] = static_cast<int>(list.size());
        });
        orphans += orphan;
    }
    failure.rethrow();
    out.without_ibp_in_h = orphans;
    for (long g = 0; g < n; ++g) out.offsets[static_cast<std::size_t>(g) + 1] += out.offsets[static_cast<std::size_t>(g)];
    out.ibp.resize(static_cast<std::size_t>(out.offsets.back()));
    out.weight.resize(out.ibp.size());
#pragma omp parallel for schedule(static)
    for (long g = 0; g < n; ++g) {
        std::size_t at = static_cast<std::size_t>(out.offsets[static_cast<std::size_t>(g)]);
        for (const auto& e : found[static_cast<std::size_t>(g)]) {
            out.ibp[at] = static_cast<int>(e.first);
            out.weight[at] = e.second < 0 ? 1.0 : cubic_spline_w(std::sqrt(e.second), h);
            ++at;
        }
    }
    return out;
}

}  // namespace mw
