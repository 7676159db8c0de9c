// Small programmatic scenes for the physics tests (the JSON route is tested in tests/cli).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "algorithms/simulation.hpp"
#include "sampling/box_particles.hpp"
#include "sampling/kdtree.hpp"

namespace mw::test {

// A box of fluid [block_lo, block_hi] in a domain [lo, hi] lined with Akinci walls at spacing r0/2,
// the first layer kWallGap r0 outside the faces (the fluid starts at rest density).
inline SimulationSetup fluid_in_box(Vec3 lo, Vec3 hi, Vec3 block_lo, Vec3 block_hi, Real r0, Real dt) {
    SimulationSetup setup;
    setup.params.domain_min = lo;
    setup.params.domain_max = hi;
    setup.params.fluid.spacing = r0;
    setup.params.fluid.support_radius = 2 * r0;
    setup.params.fluid.rest_density = 1000;
    setup.params.solver.dt = dt;
    for (const Vec3& p : fill_box_lattice(block_lo, block_hi, r0)) {
        setup.position.push_back(p);
        setup.type.push_back(kFluid);
    }
    for (const Vec3& p : sample_container_walls(lo, hi, r0 / 2, 1, kWallGap * r0)) {
        setup.position.push_back(p);
        setup.type.push_back(kStaticBoundary);
    }
    setup.velocity.assign(setup.position.size(), Vec3{0, 0, 0});
    setup.object.assign(setup.position.size(), -1);
    return setup;
}

// Host-side neighbour search for the tests' own recomputations, independent of the solver's grid
// (nanoflann, in double precision). for_each_within(x, f) calls f(k, r) for every point k (index
// into the vector given) at distance r = |x - points[k]| < h.
class PointBins {
   public:
    PointBins(const std::vector<Vec3>& points, double h) : h_(h) {
        points_.reserve(points.size());
        for (const Vec3& p : points) points_.emplace_back(p.x, p.y, p.z);
        tree_ = std::make_unique<PointTree>(points_);
    }
    PointBins(const PointBins&) = delete;  // the tree refers to points_ of this object
    PointBins& operator=(const PointBins&) = delete;
    template <class F>
    void for_each_within(Vec3 x, F&& f) const {
        tree_->within(Vec3d(x.x, x.y, x.z), h_, found_);
        for (const auto& [k, r2] : found_) f(k, std::sqrt(r2));  // nanoflann gives squared distances
    }

   private:
    std::vector<Vec3d> points_;
    double h_;
    std::unique_ptr<PointTree> tree_;  // refers to points_: built after it, destroyed before it
    mutable std::vector<std::pair<std::uint32_t, double>> found_;
};

}  // namespace mw::test
