// The velocity–position correction against the domain walls: METHOD.md's step 7 (and its position
// rule inside the PCISPH loop) for a boundary that does not move and whose mass is infinite.
//
// Why: a single Akinci layer repels a fluid particle less and less as it comes close to the layer
// (the layer's gradients cancel in its own plane), so a particle driven hard enough into a wall
// passes through it. Measured (fifteenth session): in scenes/dam_break_paper_kernel.json the
// returning wave presses a particle to 0.2 r0 from the back wall's layer at 3.7 m/s; its PCISPH
// prediction lands behind the layer, where the wall pushes it outward, and the step ends with it
// at 25 m/s through the wall (the 25 m/s "splash" and the one lost particle of the fourteenth
// session's runs).
//
// The rule, per axis-aligned wall: a fluid particle closer than `contact` to the wall's first
// particle layer and moving towards it is put back at `contact` from the layer and keeps no
// velocity into the wall (the inelastic normal rule with m_k infinite: v̂ⁿ = vⁿ_k = 0). Tangential
// velocity is kept: the walls are free-slip (∂ = 1; friction is Eq. 8's job). Inside the PCISPH
// loop only the predicted position is corrected, so the density the pressure answers is never
// that of a particle behind the wall.
//
// `contact` is the paper's r0, but never more than the distance at which fluid next to a face
// starts at rest (the gap plus r0/2: 1.1 r0 with one layer and h = 2 r0, 0.975 r0 with two), so
// a resting fluid block never starts inside the band.
#pragma once
#include "algorithms/vec3.hpp"

namespace mw {

struct WallContact {
    // The planes the fluid may not cross moving outward: the wall layers moved in by `contact`.
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
    bool active = false;

    // For a domain [domain_lo, domain_hi] whose walls' first layer lies `gap` outside the faces.
    static WallContact for_domain(Vec3 domain_lo, Vec3 domain_hi, Real gap, Real r0) {
        const Real rest = gap + r0 / 2;
        const Real contact = r0 < rest ? r0 : rest;
        const Real inward = contact - gap;  // from the face into the domain (negative: outside it)
        WallContact c;
        c.lo = Vec3{domain_lo.x + inward, domain_lo.y + inward, domain_lo.z + inward};
        c.hi = Vec3{domain_hi.x - inward, domain_hi.y - inward, domain_hi.z - inward};
        c.active = true;
        return c;
    }

    // After integration: the position back to the plane, the velocity into the wall removed.
    MW_INLINE void correct(Vec3& x, Vec3& v) const {
        if (!active) return;
        axis(x.x, v.x, lo.x, hi.x);
        axis(x.y, v.y, lo.y, hi.y);
        axis(x.z, v.z, lo.z, hi.z);
    }

    // Inside PCISPH: the predicted position x* of a particle whose predicted velocity v* moves it
    // outward.
    MW_INLINE Vec3 correct_predicted(Vec3 x, Vec3 v) const {
        if (!active) return x;
        correct(x, v);
        return x;
    }

   private:
    static MW_INLINE void axis(Real& x, Real& v, Real lo_plane, Real hi_plane) {
        if (x < lo_plane && v < Real(0)) {
            x = lo_plane;
            v = Real(0);
        } else if (x > hi_plane && v > Real(0)) {
            x = hi_plane;
            v = Real(0);
        }
    }
};

}  // namespace mw
