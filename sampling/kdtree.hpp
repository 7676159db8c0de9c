// nanoflann k-d tree over a std::vector<Vec3d> (host, double precision). Remember nanoflann's
// conventions: radiusSearch takes the SQUARED radius and always a SearchParams.
#pragma once
#include <cstdint>
#include <vector>

#include <nanoflann.hpp>

#include "sampling/mesh.hpp"

namespace mw {

struct PointCloudAdaptor {
    const std::vector<Vec3d>* points;
    std::size_t kdtree_get_point_count() const { return points->size(); }
    double kdtree_get_pt(std::size_t i, std::size_t d) const { return (*points)[i][static_cast<int>(d)]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
        return false;
    }
};

using KdTree3 = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, PointCloudAdaptor>,
                                                    PointCloudAdaptor, 3, std::uint32_t>;

// Owns the adaptor so the tree never outlives it; `points` must outlive the tree.
class PointTree {
public:
    explicit PointTree(const std::vector<Vec3d>& points)
        : adaptor_{&points}, tree_(3, adaptor_, nanoflann::KDTreeSingleIndexAdaptorParams(12)) {
        tree_.buildIndex();
    }
    PointTree(const PointTree&) = delete;
    PointTree& operator=(const PointTree&) = delete;
    // Nearest point: index and distance (index -1 when empty).
    std::pair<long, double> nearest(const Vec3d& q) const {
        if (adaptor_.points->empty()) return {-1, 0.0};
        std::uint32_t index = 0;
        double d2 = 0;
        nanoflann::KNNResultSet<double, std::uint32_t> result(1);
        result.init(&index, &d2);
        tree_.findNeighbors(result, q.data(), nanoflann::SearchParams());
        return {static_cast<long>(index), std::sqrt(d2)};
    }
    // All points within `radius` (not squared), sorted by index.
    void within(const Vec3d& q, double radius, std::vector<std::pair<std::uint32_t, double>>& out) const {
        out.clear();
        tree_.radiusSearch(q.data(), radius * radius, out, nanoflann::SearchParams(32, 0.f, false));
    }

private:
    PointCloudAdaptor adaptor_;
    KdTree3 tree_;
};

}  // namespace mw
