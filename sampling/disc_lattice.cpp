#include "sampling/disc_lattice.hpp"

#include <cmath>

namespace mw {

std::vector<Vec3> disc_lattice(Vec3 normal, Real radius, Real spacing, int dimensions) {
    // The basis from the axis least aligned with the normal, so that the cross product is large;
    // in 2D from z, so that u lies in the plane.
    const double n[3] = {normal.x, normal.y, normal.z};
    int least = 0;
    for (int a = 1; a < 3; ++a)
        if (std::fabs(n[a]) < std::fabs(n[least])) least = a;
    if (dimensions == 2) least = 2;
    double e[3] = {0, 0, 0};
    e[least] = 1;
    double u[3] = {n[1] * e[2] - n[2] * e[1], n[2] * e[0] - n[0] * e[2], n[0] * e[1] - n[1] * e[0]};
    const double length = std::sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (double& c : u) c /= length;
    const double w[3] = {n[1] * u[2] - n[2] * u[1], n[2] * u[0] - n[0] * u[2], n[0] * u[1] - n[1] * u[0]};
    const double s = spacing, r = radius;
    const long reach = static_cast<long>(std::floor(r / s + 1e-9));
    const long reach_w = dimensions == 2 ? 0 : reach;
    std::vector<Vec3> points;
    for (long j = -reach_w; j <= reach_w; ++j)
        for (long i = -reach; i <= reach; ++i) {
            if (double(i * i + j * j) * s * s > r * r * (1 + 1e-9)) continue;
            points.push_back(Vec3{Real(i * s * u[0] + j * s * w[0]), Real(i * s * u[1] + j * s * w[1]),
                                  Real(i * s * u[2] + j * s * w[2])});
        }
    return points;
}

}  // namespace mw
