// Heat conduction between fluid and moving solids: the first half of melting (METHOD.md,
// "Melting"; docs/heat.md). Every fluid particle and every surface and inner particle of an
// elastic or rigid object carries a temperature T; static walls, static boxes and static objects
// are adiabatic (no heat crosses them) and the mesh vertices (GPs) keep their initial value.
//
// The heat equation dT/dt = α ∇²T with Brookshaw's (1985) SPH Laplacian, which only needs W'
// and gives a weight that is never negative:
//
//   dT_i/dt = Σ_j c_ij (T_j - T_i),   c_ij = s (α_i + α_j) V_j F_ij,   F_ij = -W'(r_ij) / r_ij,
//
// α the particle's thermal diffusivity (its material's: the fluid's, or its object's), V_j = m/ρ_j
// for fluid and the Akinci volume V_b for a solid's particles, and s the lattice factor that makes
// the sum exact on a regular lattice at spacing r0 (pcisph_delta.hpp, laplacian_moment: at
// h = 2 r0 the raw sum is 4% slow for the cubic spline). Every particle has the same heat capacity
// per volume, so Σ_i V_i T_i is the heat, and the pair terms conserve it.
//
// Time: explicit sub-steps, as many as keep D = δt Σ_j c_ij at most 1 on a full lattice of the
// most diffusive material (then each update is a weighted mean of T_i and its neighbours', so no
// temperature leaves their range), at most `max_substeps`. A particle whose own D exceeds 1 (a
// denser neighbourhood, or a step past the cap) moves to its neighbours' weighted mean instead of
// past it: the update stays a mean, stable at any Δt, and only loses rate there.
//
// METHOD.md's backward Euler (one pass per step, stable at any Δt) was built first, as Jacobi
// sweeps of the implicit system: one sweep diffuses at 1/(1 + D) of the true rate (0.56 at a
// Fourier number α Δt / r0² of 0.2, 0.21 at 1), and reaching 5% took 4 sweeps at 0.2 and 28 at 2
// (then 11% slow). Explicit sub-steps were within 2% of the true rate at every Fourier number
// tried, in 1 pass at 0.2 and 9 at 2 (tests/core/test_heat.cpp, docs/heat.md).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include "algorithms/neighbor_grid.hpp"
#include "algorithms/neighbor_list.hpp"
#include "algorithms/particle_types.hpp"
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

// Where a particle's diffusivity and volume come from (read once per step, by the first pass).
struct HeatMaterials {
    View<const std::uint8_t> type;          // store fields
    View<const Real> density;               // fluid: V = m/ρ (this step's density)
    View<const Real> boundary_volume;       // solids' particles: V_b (this step's)
    View<const std::int32_t> solid_slot;    // solids' particles: their slot (empty without solids)
    const std::int32_t* slot_object = nullptr;  // slot -> index of its object in the setup's solids
    const Real* object_diffusivity = nullptr;   // α per object, m²/s
    Real fluid_diffusivity = 0;             // α of the fluid, m²/s
    Real fluid_mass = 0;
};

// A pass's two sums for particle i: Σ_j c_ij and Σ_j c_ij T_j (c without δt s).
struct HeatSums {
    Real weight = 0, weighted = 0;
    MW_INLINE HeatSums& operator+=(const HeatSums& o) {
        weight += o.weight;
        weighted += o.weighted;
        return *this;
    }
};

// The neighbours a fluid particle conducts with: fluid and moving solids. The lists hold the
// static boundary too, whose terms are 0 (the walls are adiabatic); the grid skips their cells.
template <class F>
MW_INLINE HeatSums sum_conducting(const GridView& grid, std::size_t i, Vec3 x, F&& f) {
    HeatSums sums = grid.sum_fluid(i, x, f);
    grid.for_each_solid(x, [&](std::uint32_t j) { sums += f(j); });
    return sums;
}
template <class F>
MW_INLINE HeatSums sum_conducting(const NeighborListView& lists, std::size_t i, Vec3 x, F&& f) {
    HeatSums sums = lists.sum_fluid(i, x, f);
    sums += lists.sum_boundary(i, x, f);
    return sums;
}

// One explicit sub-step over particles [first, first + count), from `in` to `out` (never the same):
// out_i = T_i + λ (a Σ_j c_ij T_j - g T_i), g = a Σ_j c_ij, a = δt s, λ = min(1, 1/g), with
// c_ij = (α_i V_j + (αV)_j) F_ij from the per-particle V and αV of the moving particles
// [0, moving): a static neighbour (the lists' boundary entries) reads particle 0's and adds 0.
// Otherwise branch-free terms (F is 0 out of range and for i itself), as in the PCISPH sums.
template <class Neighbors, class Kernel>
void heat_substep(const Neighbors& neighbors, std::size_t first, std::size_t count, std::size_t moving,
                  View<const Vec3> position, View<const Real> volume, View<const Real> alpha_volume,
                  View<const Real> in, View<Real> out, Real dt_times_scale, Kernel kernel) {
    parallel_for("heat_substep", count, [=] MW_HD(std::size_t k) {
        const std::size_t i = first + k;
        const Vec3 xi = position[i];
        const Real alpha_i = alpha_volume[i] / volume[i];
        const HeatSums sums = sum_conducting(neighbors, i, xi, [&](std::uint32_t j) {
            const bool conducts = j < moving;
            const std::uint32_t jj = conducts ? j : 0u;
            const Real f = conducts ? kernel.laplacian_weight_r2(norm2(xi - position[j])) : Real(0);
            const Real c = (alpha_i * volume[jj] + alpha_volume[jj]) * f;
            return HeatSums{c, c * in[jj]};
        });
        const Real g = dt_times_scale * sums.weight;
        const Real share = g > Real(1) ? Real(1) / g : Real(1);
        out[i] = in[i] + share * (dt_times_scale * sums.weighted - g * in[i]);
    });
}

// The heat stage's own buffers and its sub-steps.
class HeatConduction {
   public:
    // `moving`: the store's moving particles (the most a pass covers); `lattice_scale`: s above;
    // `d_per_dt`: D / Δt of the most diffusive material (pcisph_delta.hpp, heat_d_per_dt).
    void init(std::size_t moving, int max_substeps, double lattice_scale, double d_per_dt) {
        max_substeps_ = std::max(1, max_substeps);
        lattice_scale_ = lattice_scale;
        d_per_dt_ = d_per_dt;
        moving_ = moving;
        volume_.resize(moving);
        alpha_volume_.resize(moving);
        other_.resize(moving);
    }
    // The sub-steps a step of dt takes: D / n <= 1, at most max_substeps.
    int substeps_for(double dt) const {
        const double n = std::ceil(d_per_dt_ * dt);
        return n < 1 ? 1 : n > max_substeps_ ? max_substeps_ : static_cast<int>(n);
    }
    int last_substeps() const { return last_substeps_; }
    std::size_t bytes() const { return volume_.bytes() + alpha_volume_.bytes() + other_.bytes(); }

    // Advances `temperature` (a store field) by dt over the fluid [0, fluid_end), whose rows come
    // from `fluid_rows` (this step's lists, or the grid), and the moving solids' particles
    // [fluid_end, solid_end) (the grid). The sub-steps alternate between the store's field and
    // other_, starting where an odd or even count ends in the store.
    template <class Neighbors, class Kernel>
    void step(const Neighbors& fluid_rows, const GridView& grid, std::size_t fluid_end, std::size_t solid_end,
              View<const Vec3> position, const HeatMaterials& m, View<Real> temperature, Real dt, Kernel kernel) {
        if (solid_end == 0) return;
        const int substeps = substeps_for(double(dt));
        last_substeps_ = substeps;
        const View<const Real> stored = temperature;
        const View<Real> other = other_.view(), volume = volume_.view(), alpha_volume = alpha_volume_.view();
        parallel_for("heat_materials", solid_end, [=] MW_HD(std::size_t i) {
            other[i] = stored[i];
            const bool fluid = m.type[i] == kFluid;
            const Real v = fluid ? m.fluid_mass / m.density[i] : m.boundary_volume[i];
            const Real alpha = fluid ? m.fluid_diffusivity : m.object_diffusivity[m.slot_object[m.solid_slot[i]]];
            volume[i] = v;
            alpha_volume[i] = alpha * v;
        });
        const Real a = static_cast<Real>(double(dt) / substeps * lattice_scale_);
        // An odd count starts from the copy in other_, an even one from the store: the last lands there.
        View<Real> in = substeps % 2 == 1 ? other : temperature;
        View<Real> out = substeps % 2 == 1 ? temperature : other;
        for (int substep = 0; substep < substeps; ++substep) {
            if (fluid_end > 0)
                heat_substep(fluid_rows, 0, fluid_end, moving_, position, volume_.cview(), alpha_volume_.cview(), in,
                             out, a, kernel);
            if (solid_end > fluid_end)
                heat_substep(grid, fluid_end, solid_end - fluid_end, moving_, position, volume_.cview(),
                             alpha_volume_.cview(), in, out, a, kernel);
            std::swap(in, out);
        }
    }

   private:
    int max_substeps_ = 1;
    double lattice_scale_ = 1;
    double d_per_dt_ = 0;  // D / Δt for the most diffusive material on a full lattice
    int last_substeps_ = 0;
    std::size_t moving_ = 0;
    DeviceArray<Real> volume_;        // V per moving particle, this step's
    DeviceArray<Real> alpha_volume_;  // α V per moving particle, the same
    DeviceArray<Real> other_;         // the sub-steps' second buffer
};

MW_BACKEND_END
