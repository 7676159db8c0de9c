#include "sampling/wall_gap.hpp"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "common/errors.hpp"

namespace mw {

namespace {
std::string format_length(double x) {
    char text[32];
    std::snprintf(text, sizeof text, "%.9g", x);
    return text;
}

// Σ W over an infinite square grid of `spacing` in a plane at distance `dz`, one grid point
// straight across (in 2D: a row of points on a line). The grid's lateral offset against the fluid
// changes the first layer's density by less than 1e-4 of ρ0 for spacings up to r0/2 (the
// default); at a spacing of r0 by up to 0.3% for h = 2 to 2.5 r0 and 2% for h = 1.5 r0.
template <class Kernel>
double sheet_sum(const Kernel& kernel, double spacing, double dz) {
    const int reach = static_cast<int>(std::ceil(double(kernel.h) / spacing)) + 1;
    const int reach_j = Kernel::kDimensions == 3 ? reach : 0;
    double sum = 0;
    for (int j = -reach_j; j <= reach_j; ++j)
        for (int i = -reach; i <= reach; ++i) {
            const double r = std::sqrt((i * spacing) * (i * spacing) + (j * spacing) * (j * spacing) + dz * dz);
            sum += kernel.W(Real(r));
        }
    return sum;
}

template <class Kernel>
Real wall_gap_for(const Kernel& kernel, double r0, double s, int layers) {
    const double h = kernel.h;
    const int reach = static_cast<int>(std::ceil(h / r0)) + 1;

    // The fluid mass makes a full lattice the rest density: ρ0 = m Σ W (ρ0 cancels below, so
    // densities are in units of ρ0 and m = 1 / Σ W).
    double full = 0, half = 0;  // half: the first layer's own half-lattice, r0/2 above the face
    const int reach_j = Kernel::kDimensions == 3 ? reach : 0;
    for (int k = -reach; k <= reach; ++k)
        for (int j = -reach_j; j <= reach_j; ++j)
            for (int i = -reach; i <= reach; ++i) {
                const double w = kernel.W(Real(r0 * std::sqrt(double(i * i + j * j + k * k))));
                full += w;
                if (k >= 0) half += w;  // fluid layers at 0.5 r0 + k r0, the particle's own at k = 0
            }
    const double fluid_part = half / full;

    // Each wall layer's Akinci volume, from every layer's sheet (independent of the gap).
    std::vector<double> volume(layers);
    for (int a = 0; a < layers; ++a) {
        double sum = 0;
        for (int b = 0; b < layers; ++b) sum += sheet_sum(kernel, s, (b - a) * s);
        volume[a] = 1 / sum;
    }
    // The first fluid layer's density (units of ρ0) with the first wall layer `gap` outside the face.
    auto density = [&](double gap) {
        double wall = 0;
        for (int a = 0; a < layers; ++a) wall += volume[a] * sheet_sum(kernel, s, 0.5 * r0 + gap + a * s);
        return fluid_part + wall;
    };
    double lo = 0, hi = h + r0;  // at hi no wall particle is within h: the density is the half-lattice's
    if (!(density(lo) > 1) || !(density(hi) < 1))
        throw InputError("fluid.support_radius: no placement of the domain walls gives the fluid its rest density "
                         "with h = " + format_length(h) + " m and fluid.spacing r0 = " + format_length(r0) +
                         " m; h must exceed r0 by more than rounding");
    for (int it = 0; it < 60; ++it) {
        const double mid = 0.5 * (lo + hi);
        (density(mid) > 1 ? lo : hi) = mid;
    }
    return Real(0.5 * (lo + hi));
}
}  // namespace

Real rest_density_wall_gap(Real r0, Real h, Real boundary_spacing, int layers, KernelKind kernel, int dimensions) {
    if (!(r0 > 0) || !(h > r0) || !(boundary_spacing > 0) || layers < 1)
        throw InputError("wall gap: need spacing > 0, support radius > spacing, boundary spacing > 0, layers >= 1");
    return with_kernel(kernel, dimensions, h, [&](const auto& w) { return wall_gap_for(w, r0, boundary_spacing, layers); });
}

}  // namespace mw
