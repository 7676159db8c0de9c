// PCISPH's stiffness δ from a prototype particle with a full neighbourhood (Solenthaler &
// Pajarola 2009): δ = ρ0² / (2 Δt² m² (|Σ∇W|² + Σ|∇W|²)) over a regular lattice at spacing r0
// around the origin. The lattice sums are computed once; δ scales with 1/Δt².
#pragma once
#include <cmath>

#include "algorithms/vec3.hpp"

namespace mw {

struct PrototypeSums {
    double sum_W = 0;            // Σ_j W(x_j), the prototype's own term included
    double grad_sum_sq = 0;      // |Σ_j ∇W|²  (zero by symmetry on a full lattice)
    double sum_grad_sq = 0;      // Σ_j |∇W|²
    // Σ_j (-W'(r_j)/r_j) x_j² (one axis): Brookshaw's Laplacian on the lattice is this over Σ_j W
    // times the true one (heat.hpp rescales by its inverse).
    double laplacian_moment = 0;
};

// dimensions: 2 (lattice in the xy plane) or 3.
template <class Kernel>
PrototypeSums prototype_sums(const Kernel& kernel, double spacing, int dimensions) {
    PrototypeSums sums;
    const int reach = static_cast<int>(std::ceil(kernel.h / spacing)) + 1;
    double gx = 0, gy = 0, gz = 0;
    const int kz = dimensions == 3 ? reach : 0;
    for (int k = -kz; k <= kz; ++k)
        for (int j = -reach; j <= reach; ++j)
            for (int i = -reach; i <= reach; ++i) {
                const Vec3 x{Real(-i * spacing), Real(-j * spacing), Real(-k * spacing)};  // x_0 - x_j
                const Real r = norm(x);
                if (r >= kernel.h) continue;
                sums.sum_W += kernel.W(r);
                const Vec3 g = kernel.grad_W(x, r);
                gx += g.x;
                gy += g.y;
                gz += g.z;
                sums.sum_grad_sq += double(g.x) * g.x + double(g.y) * g.y + double(g.z) * g.z;
                // -W'(r)/r = |∇W| / r: the kernels fall monotonically.
                if (r > 0) sums.laplacian_moment += double(norm(g)) / double(r) * double(x.x) * double(x.x);
            }
    sums.grad_sum_sq = gx * gx + gy * gy + gz * gz;
    return sums;
}

// Heat conduction (heat.hpp): the factor s that makes Brookshaw's Laplacian exact on the lattice.
inline double heat_lattice_scale(const PrototypeSums& sums) { return sums.sum_W / sums.laplacian_moment; }

inline double pcisph_delta(const PrototypeSums& sums, double rest_density, double mass, double dt) {
    return rest_density * rest_density / (2.0 * dt * dt * mass * mass * (sums.grad_sum_sq + sums.sum_grad_sq));
}

}  // namespace mw
