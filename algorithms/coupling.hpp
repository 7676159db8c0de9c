// Two-way coupling, the fluid's side of it (docs/method.md, "Two-way coupling"): every force a moving solid's
// boundary particle exerted on the fluid in this step goes back to the solid, reversed, and
// reaches its IBPs, which LSM moves.
//
// 1. The reaction on each SBP and IBP of a moving solid, gathered over its fluid neighbours with
//    exactly the terms the fluid summed (no float atomics, so it is deterministic):
//      pressure (Akinci 2012; pcisph.hpp)  F_b = Σ_i m ψ_b (p_i/ρ_i²) ∇W(x*_i - x_b)
//      friction (Eq. 8, when on)           F_b = -Σ_i m (μ_w/ρ0) V_b ∇²W(x_i - x_b) (v_b - v_i)
//      interface tension (Eq. 9, SBPs)     F_s = Σ_i η_s m ρ0 V_s W(x_is) x_is / |x_is|
//                                          (interface_tension.hpp; positions of the step's start)
//    with the last PCISPH iteration's predicted positions x* (the fluid's, and the solids' where
//    PCISPH predicts them) and pressures, so that the pair's
//    two forces cancel to rounding: the fluid and the solids together conserve momentum. With the
//    velocity–position correction against solids on, an SBP's reaction also carries the impulse
//    the correction gave it at the end of the last step (solid_contact.hpp), as J / Δt.
// 2. Each IBP's force: its own reaction, plus a share of each SBP's. The shares are the transpose
//    of the interpolation that moves the SBPs (an SBP follows its triangle's GPs by barycentric
//    weights, a GP its linked IBPs by Eq. 19's normalised weights): an SBP's shares sum to 1, so
//    no force is lost or made, and the work the force does on the SBP is the work its shares do
//    on the IBPs, up to Eq. 19's rotation term. docs/method.md's Eq. 10 as printed,
//    F_d = Σ_s W(x_ds) F_s / Σ_s W(x_ds), averages instead of sharing: an IBP next to n SBPs
//    takes about one SBP's force, not n shares of theirs, so the total on a body is not the sum
//    of its SBPs' forces (docs/coupling.md).
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include "algorithms/lsm_regions.hpp"
#include "algorithms/neighbor_grid.hpp"
#include "algorithms/pcisph.hpp"

namespace mw {

// Host, once: the SBP -> IBP shares in compressed rows by IBP slot (offsets[ibp_count + 1]),
// each row ordered by SBP, so that the per-IBP sum has one fixed order.
struct SurfaceShares {
    std::vector<std::uint32_t> offsets, sbp;  // sbp: SBP index 0 .. sbp_count
    std::vector<Real> weight;
};
inline SurfaceShares surface_shares(const LsmHostLayout& L) {
    // Each SBP's share of each IBP: Σ over its corners of bary_c × (the corner GP's Eq. 19 weight).
    std::vector<std::vector<std::pair<std::uint32_t, double>>> rows(L.ibp_count);
    std::vector<std::pair<std::uint32_t, double>> share;  // (IBP slot, weight) of one SBP
    for (std::size_t k = 0; k < L.sbp_count; ++k) {
        const SbpLink& link = L.sbp[k];
        const double bary[3] = {link.bary.x, link.bary.y, link.bary.z};
        share.clear();
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t g = link.corner[c];
            for (std::uint32_t e = L.gp_offsets[g]; e < L.gp_offsets[g + 1]; ++e)
                share.emplace_back(L.gp_links[e], bary[c] * double(L.gp_weights[e]));
        }
        std::sort(share.begin(), share.end());
        double total = 0;
        for (const auto& s : share) total += s.second;
        // Normalised in double, so that the shares of one SBP sum to 1 whatever the barycentric
        // weights' rounding; an IBP reached through two corners gets one merged share.
        for (std::size_t e = 0; e < share.size();) {
            const std::uint32_t d = share[e].first;
            double w = 0;
            for (; e < share.size() && share[e].first == d; ++e) w += share[e].second;
            if (total != 0 && w != 0) rows[d].emplace_back(std::uint32_t(k), w / total);
        }
    }
    SurfaceShares out;
    out.offsets.assign(1, 0);
    for (const auto& row : rows) {
        for (const auto& e : row) {
            out.sbp.push_back(e.first);
            out.weight.push_back(Real(e.second));
        }
        out.offsets.push_back(std::uint32_t(out.sbp.size()));
    }
    return out;
}

}  // namespace mw

MW_BACKEND_BEGIN

// What the two kernels read and write, by solid slot (solid_bodies.hpp: IBPs, then SBPs, then GPs).
struct CouplingData {
    const std::uint32_t* store_of_slot = nullptr;
    std::uint32_t ibp_count = 0, sbp_count = 0;
    Vec3* reaction = nullptr;  // per IBP and SBP slot, this step's
    Vec3* force = nullptr;     // per IBP: what LSM applies
    const std::uint32_t* share_offsets = nullptr;
    const std::uint32_t* share_sbp = nullptr;
    const Real* share_weight = nullptr;
    // The impulses the velocity–position correction gave the SBPs in the last step (per SBP;
    // null without it, solid_contact.hpp): they join this step's reaction as J / Δt.
    const Vec3* sbp_contact_impulse = nullptr;
    Real inverse_dt = 0;
    // Interface tension's η per SBP (interface_tension.hpp); null: none.
    const Real* sbp_eta = nullptr;
};

// The pairs the fluid summed: in grid mode all in the 27 cells (the relation is symmetric:
// b is in the cells around i exactly when i is in those around b); with neighbour lists only
// those within `list_radius` of each other at the start of the step, tested as the lists'
// build tests them (neighbor_list.hpp). list_radius 0: grid mode.
struct FluidPairs {
    GridView grid;
    std::size_t fluid_end = 0, solid_end = 0;  // the moving solids' boundary particles: [fluid_end, solid_end)
    Real list_radius2 = 0;
    // Where PCISPH met the solids' particles (pcisph.hpp): the reaction meets them there too.
    SolidLookahead lookahead;
};

template <class Kernel>
void fluid_reaction_on_solids(const DeviceContext& device, const FluidPairs pairs, const CouplingData d, View<const Vec3> position,
                              View<const Vec3> velocity, View<const Vec3> predicted, View<const Real> boundary_volume,
                              View<const Real> pressure_term, FluidConstants<Kernel> c, bool friction) {
    const Real pressure_scale = c.mass * c.rest_density;         // m ρ0 (ψ_b = ρ0 V_b)
    const Real friction_scale = -c.mass * c.wall_viscosity / c.rest_density;  // -m μ_w / ρ0
    const bool lists = pairs.list_radius2 > Real(0);
    parallel_for(device, "coupling_reaction", std::size_t(d.ibp_count) + d.sbp_count, [=] MW_HD(std::size_t s) {
        const std::uint32_t b = d.store_of_slot[s];
        // A solid particle that left the grid (counted as lost) meets no fluid.
        if (b < pairs.fluid_end || b >= pairs.solid_end) {
            d.reaction[s] = Vec3{0, 0, 0};
            return;
        }
        const Vec3 xb = position[b], vb = velocity[b];
        const Real eta = d.sbp_eta && s >= d.ibp_count ? d.sbp_eta[s - d.ibp_count] : Real(0);
        Vec3 pressure_sum{0, 0, 0}, friction_sum{0, 0, 0}, tension_sum{0, 0, 0};
        pairs.grid.for_each_fluid(xb, [&](std::uint32_t i) {
            const Vec3 xi = position[i];
            const Real paired = lists ? (norm2(xi - xb) < pairs.list_radius2 ? Real(1) : Real(0)) : Real(1);
            const Vec3 r = predicted[i] - pairs.lookahead.place(b, xb);
            pressure_sum += (paired * pressure_term[i]) * c.kernel.grad_W_r2(r, norm2(r));
            if (friction) friction_sum += c.kernel.laplacian_visc_r2(norm2(xi - xb)) * (vb - velocity[i]);
            if (eta > Real(0)) {
                const Vec3 x_is = xi - xb;
                const Real r2 = norm2(x_is);
                const Real w = c.kernel.W_r2(r2);
                if (w > Real(0) && r2 > Real(0)) tension_sum += (w / std::sqrt(r2)) * x_is;
            }
        });
        const Real vb_volume = boundary_volume[b];
        Vec3 reaction = (pressure_scale * vb_volume) * pressure_sum + (friction_scale * vb_volume) * friction_sum +
                        (pressure_scale * vb_volume * eta) * tension_sum;
        if (d.sbp_contact_impulse && s >= d.ibp_count)
            reaction += d.inverse_dt * d.sbp_contact_impulse[s - d.ibp_count];
        d.reaction[s] = reaction;
    });
}

// Each IBP's force: its own reaction and its shares of the SBPs' (see the top of the file).
inline void gather_solid_forces(const DeviceContext& device, const CouplingData d) {
    parallel_for(device, "coupling_to_ibps", d.ibp_count, [=] MW_HD(std::size_t s) {
        Vec3 f = d.reaction[s];
        for (std::uint32_t e = d.share_offsets[s]; e < d.share_offsets[s + 1]; ++e)
            f += d.share_weight[e] * d.reaction[d.ibp_count + d.share_sbp[e]];
        d.force[s] = f;
    });
}

MW_BACKEND_END
