// GPs: the mesh vertices, each linked to the IBPs within the support radius h in the rest shape,
// with cubic-spline kernel weights, ready for the GP interpolation (docs/method.md, Eq. 19):
//   x_g = Σ_d W(x0_gd) (R_d x0_gd + g_d) / Σ_d W(x0_gd).
#pragma once
#include <cmath>
#include <cstdint>
#include <vector>

#include "sampling/mesh.hpp"

namespace mw {

// Cubic spline with support radius h: σ(6(q³ − q²) + 1) for q = r/h ≤ 1/2, σ 2(1 − q)³ for
// 1/2 < q ≤ 1, 0 beyond; σ = 8 / (π h³).
inline double cubic_spline_w(double r, double h) {
    const double q = r / h;
    const double sigma = 8.0 / (M_PI * h * h * h);
    if (q <= 0.5) return sigma * (6.0 * (q * q * q - q * q) + 1.0);
    if (q <= 1.0) return sigma * 2.0 * (1.0 - q) * (1.0 - q) * (1.0 - q);
    return 0.0;
}

struct GeometryLinks {
    std::vector<Vec3d> positions;  // the mesh vertices (rest shape)
    // CSR: IBPs linked to GP g are ibp[offsets[g] .. offsets[g+1]), with kernel weights weight[...]
    // (not normalised; Eq. 19 divides by their sum). Sorted by IBP index.
    std::vector<int> offsets;
    std::vector<int> ibp;
    std::vector<double> weight;
    // GPs with no IBP within h (thin features at coarse r0): linked to their nearest IBP with
    // weight 1 so that Eq. 19 stays defined; counted here so callers can warn.
    std::size_t without_ibp_in_h = 0;
    std::size_t count() const { return positions.size(); }
};

GeometryLinks link_geometry(const TriangleMesh& mesh, const std::vector<Vec3d>& ibp_positions, double support_radius);

}  // namespace mw
