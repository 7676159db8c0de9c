// What follows the IBPs each step (device): GPs by the paper's Eq. 19, SBPs by the barycentric
// weights of their triangle's GPs, with the deformed triangle's normal (a rod's: its segment's
// tangent; a 2D object's: its outline edge's normal) and interpolated velocity.
//
// Eq. 19: x_g = Σ_d W_gd (R_d (x0_g - x0_d) + x_d) / Σ_d W_gd over the IBPs d linked to g, R_d
// the mean rotation of d's regions. The paper writes the IBP's goal g_d where we use the IBP's
// position after this step's update: with α < 1 or external forces the goal is a step behind
// the particles, and the surface the fluid sees must sit on the particles that carry the forces.
// GP velocity is its displacement over the step; SBP velocity interpolates the GP velocities.
// An SBP sits its inset inside its triangle along the deformed normal (sampling/surface_inset.hpp).
#pragma once
#include <cmath>

#include "algorithms/lsm_regions.hpp"
#include "algorithms/solid_face.hpp"
#include "algorithms/wall_contact.hpp"
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

struct InterpolationData {
    Vec3* position = nullptr;  // the particle store
    Vec3* velocity = nullptr;
    const std::uint32_t* store_of_slot = nullptr;
    const Vec3* ibp_rest = nullptr;
    const Mat3* mean_rotation = nullptr;
    std::uint32_t sbp_first = 0, gp_first = 0;  // first slot of SBPs and GPs
    std::uint32_t gp_count = 0, sbp_count = 0;
    const Vec3* gp_rest = nullptr;
    const std::uint32_t* gp_offsets = nullptr;
    const std::uint32_t* gp_links = nullptr;  // IBP slots
    const Real* gp_weights = nullptr;         // normalised
    const SbpLink* sbp = nullptr;
    Vec3* sbp_normal = nullptr;
    // Each SBP's inset this step (null: none set in), faded near the domain walls [wall_lo,
    // wall_hi] and the static boxes over `inset_fade` (solid_face.hpp, faded_inset).
    Real* sbp_inset = nullptr;
    Vec3 wall_lo{0, 0, 0}, wall_hi{0, 0, 0};
    Real inset_fade = 0;
    View<const ContactBox> boxes;  // the static boxes, faded near as the walls are
};

inline void interpolate_geometry(const DeviceContext& device, const InterpolationData d, Real dt) {
    const Real inv_dt = Real(1) / dt;
    parallel_for(device, "solid_gp", d.gp_count, [=] MW_HD(std::size_t g) {
        const Vec3 x0 = d.gp_rest[g];
        Vec3 x{0, 0, 0};
        for (std::uint32_t k = d.gp_offsets[g]; k < d.gp_offsets[g + 1]; ++k) {
            const std::uint32_t s = d.gp_links[k];
            x += d.gp_weights[k] * (d.mean_rotation[s] * (x0 - d.ibp_rest[s]) + d.position[d.store_of_slot[s]]);
        }
        const std::uint32_t i = d.store_of_slot[d.gp_first + g];
        d.velocity[i] = inv_dt * (x - d.position[i]);
        d.position[i] = x;
    });
}

inline void interpolate_surface(const DeviceContext& device, const InterpolationData d) {
    parallel_for(device, "solid_sbp", d.sbp_count, [=] MW_HD(std::size_t k) {
        const SbpLink link = d.sbp[k];
        Vec3 c[3], x{0, 0, 0}, v{0, 0, 0};
        const Real b[3] = {link.bary.x, link.bary.y, link.bary.z};
        for (int j = 0; j < 3; ++j) {
            const std::uint32_t gi = d.store_of_slot[d.gp_first + link.corner[j]];
            c[j] = d.position[gi];
            x += b[j] * c[j];
            v += b[j] * d.velocity[gi];
        }
        // A rod's SBP stores its segment's tangent (solid_face.hpp, kSbpAround).
        const Vec3 n = link.is_segment() ? link.face_direction(c) : link.sign * link.face_direction(c);
        const Real len = norm(n);
        Vec3 normal = d.sbp_normal[k];  // a collapsed triangle keeps its last normal
        if (len > Real(0)) {
            normal = n / len;
            d.sbp_normal[k] = normal;
        }
        const std::uint32_t i = d.store_of_slot[d.sbp_first + k];
        Real inset = link.inset;
        if (d.sbp_inset) {
            inset = faded_inset(inset, x, normal, d.wall_lo, d.wall_hi, d.inset_fade, d.boxes);
            d.sbp_inset[k] = inset;
        }
        d.position[i] = x - inset * normal;
        d.velocity[i] = v;
    });
}

MW_BACKEND_END
