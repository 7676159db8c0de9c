// The velocity–position correction against moving solids (docs/method.md; the paper's §3.3,
// Eqs. 11-17), after the fluid's integration: a fluid particle near an elastic or rigid object's
// surface particles (SBPs) faces the virtual boundary particle k built from those within r0
// (virtual_boundary.hpp); when it lies within the band c of k's surface and moves into it, it
// collides with k, and the pair exchanges momentum.
//
// Per fluid particle i that collides (a gather over the SBPs near it; nothing races), with depth
// its distance in front of k's surface (SolidSurface::collides):
//   position: x_i moves along n_k until it is c in front of k's surface (only the normal part:
//           the paper's x̂ = x_k + r0 n_k would also slide it sideways onto x_k)
//   velocity: with the relative velocity u = v_i - v_k split along n_k (u_n) and across it
//           (u_t), Δv_i = -(m_k / (m_i + m_k)) (u_n + (1 - ∂) u_t): the paper's Eqs. 15 and 17
//           written in inverse masses, so that an infinitely heavy k (one-way coupling, pinned
//           lattice) gives v̂ⁿ_i = vⁿ_k exactly
//   the solid: gets the impulse J = -m_i Δv_i, shared among the SBPs k was built from by
//           w_s / Σ w (the paper's Eq. 18 projects the change on each SBP's velocity, which is
//           undefined for an SBP at rest; docs/method.md). Each SBP gathers its shares from the fluid
//           particles within r0 of its face point (solid_face.hpp), with the same weights on the
//           same numbers, so the shares add up to J.
//
// The SBPs' contact mass: what LSM moves when a force lands on the SBP (docs/coupling.md). Its
// force goes to IBPs d by the shares w_sd (coupling.hpp); a force F on IBP d, split among its n_d
// regions and moving each region r (mass M_r) as a rigid body, accelerates d by
// F Σ_r (1/M_r) / n_d², so 1/m_d = Σ_r (1/M_r) / n_d² (a rigid object's one region: 1/M), and the
// SBP's 1/m_s = Σ_d w_sd / m_d (a melting lattice's exposed vertex is an IBP: its own 1/m_d,
// melting_faces.hpp). Rotation is left out: an off-centre hit on a rigid body moves the
// point a little more than this says. Pinned IBPs are infinitely heavy. One-way coupling: every
// SBP is (the solid feels nothing), and no impulse is kept.
//
// The solid's side lands one step late: the SBPs' impulses J_s wait until the next step's
// coupling, which adds J_s / Δt to their reaction (so the momentum is exact whatever that Δt is).
//
// Both gathers look for pairs around the cells the particles were sorted into at the start of the
// step (grid.for_each_*_around_particle), not around where they are now: the pairs visited are
// then the same from either side however far they moved, so the impulses the SBPs gather add up
// to what the fluid gave. (Searched around their current positions, a throw at 8 m/s and
// Δt = 4 ms loses 5.3e-3 of its momentum; as written, 3e-7.) A pair is visited for certain while the two
// moved less than h - r0 together in the step (r0 at h = 2 r0); a pair missed is missed by both.
#pragma once
#include <cstdint>
#include <vector>

#include "algorithms/coupling.hpp"
#include "algorithms/lsm_regions.hpp"
#include "algorithms/virtual_boundary.hpp"
#include "algorithms/wall_contact.hpp"

namespace mw {

// Host, once: each SBP's inverse contact mass (see the top of the file), by SBP index.
inline std::vector<Real> sbp_inverse_contact_mass(const LsmHostLayout& L, const SurfaceShares& shares) {
    std::vector<Real> inverse(L.sbp_count, Real(0));
    for (std::size_t d = 0; d < L.ibp_count; ++d) {
        if (L.ibp_pinned[d]) continue;
        const std::uint32_t begin = L.ibp_regions_begin[d], end = L.ibp_regions_end[d];
        double sum = 0;
        for (std::uint32_t e = begin; e < end; ++e) sum += 1.0 / double(L.region_mass[L.member_index[e]]);
        const double regions = double(end - begin);
        const double ibp_inverse = regions > 0 ? sum / (regions * regions) : 1.0 / double(L.ibp_mass[d]);
        for (std::uint32_t e = shares.offsets[d]; e < shares.offsets[d + 1]; ++e)
            inverse[shares.sbp[e]] += Real(double(shares.weight[e]) * ibp_inverse);
    }
    return inverse;
}

}  // namespace mw

MW_BACKEND_BEGIN

// What the correction reads and writes.
struct SolidContactData {
    SolidSurface surface;
    const std::uint32_t* store_of_slot = nullptr;
    Vec3* impulse_per_weight = nullptr;      // per fluid particle, J / Σ w (two-way only)
    Vec3* sbp_impulse = nullptr;             // per SBP, what it got in this step (two-way only)
    // Per IBP slot, what a melting lattice's exposed vertex got in this step (two-way, with a
    // melting object only).
    Vec3* lattice_impulse = nullptr;
    Real slip = 1;                           // ∂: 0 no-slip, 1 free slip
    Real fluid_inverse_mass = 0;             // 1 / m_i
    Real dt = 0;                             // the step: a particle started it at x - dt v
};

// Per fluid particle: the corrected position and velocity into (out_position, out_velocity) —
// the store itself in one-way coupling, where nothing reads the old values afterwards — and with
// two-way coupling J / Σ w for the SBPs' gather. The walls' correction follows a corrected
// particle, as it does the integration (a particle pushed out of a solid must not end up beyond
// a wall's layer).
inline void correct_fluid_at_solids(const DeviceContext& device, std::size_t fluid_count, View<const Vec3> position,
                                    View<const Vec3> velocity, View<Vec3> out_position, View<Vec3> out_velocity,
                                    const SolidContactData d, const WallContact walls) {
    parallel_for(device, "solid_contact_fluid", fluid_count, [=] MW_HD(std::size_t i) {
        const Vec3 x = position[i], v = velocity[i];
        const VirtualBoundary k = d.surface.collide(static_cast<std::uint32_t>(i), x, x - d.dt * v, position,
                                                    velocity, d.impulse_per_weight != nullptr);
        Vec3 xc = x, vc = v, impulse{0, 0, 0};
        Real depth = 0;
        if (d.surface.collides(k, x, v, depth)) {
            const Vec3 nk = k.normal;
            xc = x + (d.surface.band - depth) * nk;
            // Δv_i = -(m_k / (m_i + m_k)) (u_n + (1 - ∂) u_t), and the solid's J = -m_i Δv_i.
            const Vec3 u = v - k.velocity;
            const Vec3 u_normal = dot(u, nk) * nk;
            const Vec3 change = u_normal + (Real(1) - d.slip) * (u - u_normal);
            const Real share = d.fluid_inverse_mass / (d.fluid_inverse_mass + k.inverse_mass);
            vc = v - share * change;
            impulse = (share / d.fluid_inverse_mass) * change;
            walls.correct(xc, vc);
        }
        out_position[i] = xc;
        out_velocity[i] = vc;
        if (d.impulse_per_weight)
            d.impulse_per_weight[i] = k.weight > Real(0) ? (Real(1) / k.weight) * impulse : impulse;
    });
}

// Per SBP (two-way): its shares of the impulses of the fluid particles that collided with the
// virtual particles it is part of, from the fluid's positions before the correction.
inline void gather_sbp_impulses(const DeviceContext& device, std::size_t fluid_end, std::size_t solid_end, View<const Vec3> position,
                                const SolidContactData d) {
    parallel_for(device, "solid_contact_sbp", d.surface.sbp_count, [=] MW_HD(std::size_t k) {
        const SolidSurface& surface = d.surface;
        const std::uint32_t b = d.store_of_slot[surface.ibp_count + k];
        Vec3 sum{0, 0, 0};
        if (b >= fluid_end && b < solid_end) {  // an SBP that left the grid meets no fluid
            const Vec3 xs = surface.faces().at(position[b], static_cast<std::uint32_t>(k));
            surface.grid.for_each_fluid_around_particle(b, [&](std::uint32_t i) {
                const Real w = contact_weight(position[i], xs, surface.reach);
                if (w > Real(0)) sum += w * d.impulse_per_weight[i];
            });
        }
        d.sbp_impulse[k] = sum;
    });
}

// Per IBP slot (two-way, with a melting object): an exposed lattice vertex's shares, as the SBPs'
// above; the other slots get none.
inline void gather_lattice_impulses(const DeviceContext& device, std::size_t fluid_end, std::size_t solid_end,
                                    View<const Vec3> position, const SolidContactData d) {
    parallel_for(device, "solid_contact_lattice", d.surface.ibp_count, [=] MW_HD(std::size_t s) {
        const SolidSurface& surface = d.surface;
        const std::uint32_t b = d.store_of_slot[s];
        Vec3 sum{0, 0, 0};
        if (b >= fluid_end && b < solid_end && surface.type[b] == kSurfaceBoundary) {
            const Vec3 xs = surface.lattice_face(position[b], static_cast<std::uint32_t>(s));
            surface.grid.for_each_fluid_around_particle(b, [&](std::uint32_t i) {
                const Real w = contact_weight(position[i], xs, surface.reach);
                if (w > Real(0)) sum += w * d.impulse_per_weight[i];
            });
        }
        d.lattice_impulse[s] = sum;
    });
}

// Two-way: the corrected fluid back into the store.
inline void apply_fluid_correction(const DeviceContext& device, std::size_t fluid_count, View<const Vec3> corrected_position,
                                   View<const Vec3> corrected_velocity, View<Vec3> position, View<Vec3> velocity) {
    parallel_for(device, "solid_contact_apply", fluid_count, [=] MW_HD(std::size_t i) {
        position[i] = corrected_position[i];
        velocity[i] = corrected_velocity[i];
    });
}

MW_BACKEND_END
