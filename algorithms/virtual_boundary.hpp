// The virtual boundary particle of the velocity–position correction against moving solids (the
// paper's Eq. 11; METHOD.md step 7): what a fluid particle collides with when it comes too close
// to an elastic or rigid object's surface particles (SBPs). Read by the correction after the
// integration (solid_contact.hpp) and by its position rule inside the PCISPH loop (pcisph.hpp).
//
//   P     = the SBPs s with |x_i - x_s| < r0 and (v_i - v_s)·n_s < 0 (the paper's test)
//   w_s   = (1 - |x_i - x_s| / r0)³ (the paper's W(x, r0), from [YLHQ12])
//   x_k, v_k, n_k = the w-weighted means over P (n_k normalised); 1/m_k the w-weighted mean of
//           the SBPs' inverse contact masses (0: infinitely heavy)
// The paper weights by m_s w_s; weighting by w_s alone keeps infinitely heavy SBPs (one-way
// coupling, pinned lattice) finite, and the contact masses of one object's SBPs differ little.
//
// The correction then acts only within the band c = kMovingSolidContact r0 of the virtual
// particle's plane: fluid at rest lies 0.65-0.8 r0 from an object's SBPs (0.81 r0 under a
// floating box, docs/coupling.md), which a band of r0 would hold on its edge, as it did at the
// walls before their band was narrowed (wall_contact.hpp). The test radius stays r0, so that
// fluid up to r0 inside the surface is still found and put back.
#pragma once
#include <cmath>
#include <cstdint>

#include "algorithms/neighbor_grid.hpp"
#include "algorithms/particle_types.hpp"

namespace mw {

// The pair test and weight, one expression wherever it is evaluated (the fluid's gather and the
// SBPs' must agree to the bit): w_s when fluid particle (x, v) is within `reach` of SBP s and
// moving into it, else 0.
MW_INLINE Real penetration_weight(Vec3 x, Vec3 v, Vec3 xs, Vec3 vs, Vec3 ns, Real reach) {
    const Vec3 d = x - xs;
    const Real d2 = norm2(d);
    if (!(d2 < reach * reach) || !(dot(v - vs, ns) < Real(0))) return Real(0);
    const Real t = Real(1) - std::sqrt(d2) / reach;
    return t * t * t;
}

struct VirtualBoundary {
    Real weight = 0;  // Σ w_s; 0: no SBP in P
    Vec3 position{0, 0, 0}, velocity{0, 0, 0}, normal{0, 0, 0};
    Real inverse_mass = 0;
    MW_INLINE bool found() const { return weight > Real(0); }
};

}  // namespace mw

MW_BACKEND_BEGIN

// The moving solids' surface as the fluid sees it. Default-constructed: none (no gather).
struct SolidSurface {
    GridView grid;
    View<const std::uint8_t> type;  // store fields
    View<const std::int32_t> solid_slot;
    const Vec3* sbp_normal = nullptr;  // by SBP index; null: no correction against solids
    std::uint32_t ibp_count = 0, sbp_count = 0;  // SBP k has solid slot ibp_count + k
    Real band = 0;   // c, m
    Real reach = 0;  // r0, m

    MW_INLINE bool active() const { return sbp_normal != nullptr; }

    // The virtual particle that fluid particle i at (x, v) collides with: a gather over the SBPs
    // around the cell i was sorted into at this step's build (neighbor_grid.hpp), from the store's
    // positions and velocities. A virtual particle whose normals cancel is none.
    MW_INLINE VirtualBoundary collide(std::uint32_t i, Vec3 x, Vec3 v, View<const Vec3> position,
                                      View<const Vec3> velocity, const Real* sbp_inverse_mass) const {
        VirtualBoundary k;
        Vec3 normal_sum{0, 0, 0};
        grid.for_each_solid_around_particle(i, [&](std::uint32_t j) {
            if (type[j] != kSurfaceBoundary) return;
            const std::uint32_t s = static_cast<std::uint32_t>(solid_slot[j]) - ibp_count;
            const Vec3 xs = position[j], vs = velocity[j], ns = sbp_normal[s];
            const Real w = penetration_weight(x, v, xs, vs, ns, reach);
            if (!(w > Real(0))) return;
            k.weight += w;
            k.position += w * xs;
            k.velocity += w * vs;
            normal_sum += w * ns;
            if (sbp_inverse_mass) k.inverse_mass += w * sbp_inverse_mass[s];
        });
        const Real length = norm(normal_sum);
        if (!(k.weight > Real(0)) || !(length > Real(0))) return VirtualBoundary{};
        const Real inv_w = Real(1) / k.weight;
        k.position = inv_w * k.position;
        k.velocity = inv_w * k.velocity;
        k.normal = (Real(1) / length) * normal_sum;
        k.inverse_mass *= inv_w;
        return k;
    }

    // The position rule alone, for a PCISPH prediction x* with velocity v* (against the SBPs where
    // they are at the start of the step, where the density sees them): x* moves along n_k until
    // it is c from the virtual particle's plane.
    MW_INLINE Vec3 correct_predicted(std::uint32_t i, Vec3 x, Vec3 v, View<const Vec3> position,
                                     View<const Vec3> velocity) const {
        const VirtualBoundary k = collide(i, x, v, position, velocity, nullptr);
        if (!k.found()) return x;
        const Real depth = dot(x - k.position, k.normal);
        return depth < band ? x + (band - depth) * k.normal : x;
    }
};

MW_BACKEND_END
