#include "sampling/winding_number.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace mw {

namespace {
double solid_angle(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& q) {
    const Vec3d a = a0 - q, b = b0 - q, c = c0 - q;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    const double num = a.dot(b.cross(c));
    const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
    return 2.0 * std::atan2(num, den);
}
constexpr int kLeafSize = 8;
}  // namespace

FastWindingNumber::FastWindingNumber(const TriangleMesh& mesh, double beta) : mesh_(mesh), beta_(beta) {
    order_.resize(mesh.triangles.size());
    std::iota(order_.begin(), order_.end(), 0);
    nodes_.reserve(2 * mesh.triangles.size() / kLeafSize + 2);
    if (!order_.empty()) build(0, static_cast<int>(order_.size()));
}

int FastWindingNumber::build(int first, int count) {
    const int id = static_cast<int>(nodes_.size());
    nodes_.push_back(Node{Vec3d::Zero(), Vec3d::Zero(), 0.0, first, count, -1, -1});
    Vec3d an = Vec3d::Zero(), c = Vec3d::Zero(), lo = Vec3d::Constant(1e300), hi = Vec3d::Constant(-1e300);
    double area = 0;
    for (int i = first; i < first + count; ++i) {
        const std::size_t t = static_cast<std::size_t>(order_[static_cast<std::size_t>(i)]);
        const Vec3d a = mesh_.corner(t, 0), b = mesh_.corner(t, 1), d = mesh_.corner(t, 2);
        const Vec3d n = 0.5 * (b - a).cross(d - a);
        an += n;
        const double ar = n.norm();
        area += ar;
        c += ar * (a + b + d) / 3.0;
        const Vec3d cen = (a + b + d) / 3.0;
        lo = lo.cwiseMin(cen);
        hi = hi.cwiseMax(cen);
    }
    c = area > 0 ? Vec3d(c / area) : Vec3d(0.5 * (lo + hi));
    double r = 0;
    for (int i = first; i < first + count; ++i) {
        const std::size_t t = static_cast<std::size_t>(order_[static_cast<std::size_t>(i)]);
        for (int k = 0; k < 3; ++k) r = std::max(r, (mesh_.corner(t, k) - c).norm());
    }
    nodes_[static_cast<std::size_t>(id)] = Node{c, an, r, first, count, -1, -1};
    if (count > kLeafSize) {
        int axis = 0;
        (hi - lo).maxCoeff(&axis);
        const int mid = first + count / 2;
        auto centroid = [&](int t) {
            const std::size_t s = static_cast<std::size_t>(t);
            return mesh_.corner(s, 0)[axis] + mesh_.corner(s, 1)[axis] + mesh_.corner(s, 2)[axis];
        };
        std::nth_element(order_.begin() + first, order_.begin() + mid, order_.begin() + first + count,
                         [&](int a, int b) { return centroid(a) < centroid(b); });
        const int left = build(first, mid - first);
        const int right = build(mid, first + count - mid);
        nodes_[static_cast<std::size_t>(id)].left = left;
        nodes_[static_cast<std::size_t>(id)].right = right;
    }
    return id;
}

double FastWindingNumber::exact_range(const Vec3d& q, int first, int count) const {
    double sum = 0;
    for (int i = first; i < first + count; ++i) {
        const std::size_t t = static_cast<std::size_t>(order_[static_cast<std::size_t>(i)]);
        sum += solid_angle(mesh_.corner(t, 0), mesh_.corner(t, 1), mesh_.corner(t, 2), q);
    }
    return sum;
}

double FastWindingNumber::evaluate(const Vec3d& q) const {
    if (nodes_.empty()) return 0;
    double sum = 0;
    int stack[256];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& n = nodes_[static_cast<std::size_t>(stack[--top])];
        const Vec3d d = n.center - q;
        const double dist = d.norm();
        if (dist > beta_ * n.radius) {
            sum += d.dot(n.area_normal) / (dist * dist * dist);  // dipole: solid angle of the cluster
        } else if (n.left < 0) {
            sum += exact_range(q, n.first, n.count);
        } else {
            stack[top++] = n.left;
            stack[top++] = n.right;
        }
    }
    return sum / (4.0 * M_PI);
}

double FastWindingNumber::evaluate_exact_near_half(const Vec3d& q, double band) const {
    const double fast = evaluate(q);
    if (std::abs(fast - 0.5) > band) return fast;
    return exact_range(q, 0, static_cast<int>(order_.size())) / (4.0 * M_PI);
}

}  // namespace mw
