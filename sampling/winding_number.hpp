// Generalized winding number (Jacobson et al. 2013) of a triangle mesh, fast enough to refine the
// few lattice points the ray vote leaves undecided. A bounding-volume hierarchy over the
// triangles stores each node's area-weighted normal sum and centre; far nodes (distance > beta
// times their radius) contribute their dipole term (Barill et al. 2018, first order), near
// leaves the exact signed solid angles. evaluate_exact_near_half() re-does the sum exactly when
// the fast value lies within `band` of 1/2, so the inside decision (w > 1/2) is exact.
#pragma once
#include <vector>

#include "sampling/mesh.hpp"

namespace mw {

class FastWindingNumber {
public:
    explicit FastWindingNumber(const TriangleMesh& mesh, double beta = 2.0);
    double evaluate(const Vec3d& q) const;
    // The fast value, or the exact one when the fast one is within `band` of 1/2.
    double evaluate_exact_near_half(const Vec3d& q, double band = 0.05) const;

private:
    struct Node {
        Vec3d center;       // area-weighted centroid
        Vec3d area_normal;  // Σ area × unit normal
        double radius;      // max distance from center to a vertex in the node
        int first, count;  // triangle range in order_
        int left, right;   // children, -1 for a leaf
    };
    double exact_range(const Vec3d& q, int first, int count) const;
    int build(int first, int count);
    const TriangleMesh& mesh_;
    std::vector<int> order_;
    std::vector<Node> nodes_;
    double beta_;
};

}  // namespace mw
