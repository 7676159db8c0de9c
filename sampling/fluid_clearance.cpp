#include "sampling/fluid_clearance.hpp"

#include "sampling/kdtree.hpp"

namespace mw {

std::vector<std::uint8_t> points_solids_occupy(const std::vector<Vec3>& fluid, const std::vector<Vec3>& solid_points,
                                               const std::vector<Eigen::AlignedBox3d>& boxes, Real clearance) {
    const auto to_vec3d = [](Vec3 x) { return Vec3d(x.x, x.y, x.z); };
    std::vector<std::uint8_t> occupied(fluid.size(), 0);
    std::vector<Vec3d> solid(solid_points.size());
    Eigen::AlignedBox3d reach;  // where a solid can occupy anything at all (empty to start with)
    for (std::size_t i = 0; i < solid_points.size(); ++i) reach.extend(solid[i] = to_vec3d(solid_points[i]));
    for (const Eigen::AlignedBox3d& box : boxes) reach.extend(box);
    if (reach.isEmpty()) return occupied;
    reach.min().array() -= clearance;
    reach.max().array() += clearance;
    const PointTree tree(solid);
    const double kept_at = double(clearance) * (1 - 1e-4);
    for (std::size_t i = 0; i < fluid.size(); ++i) {
        const Vec3d x = to_vec3d(fluid[i]);
        if (!reach.contains(x)) continue;
        bool inside = false;
        for (const Eigen::AlignedBox3d& box : boxes) inside = inside || box.contains(x);
        occupied[i] = inside || (!solid.empty() && tree.nearest(x).second < kept_at);
    }
    return occupied;
}

}  // namespace mw
