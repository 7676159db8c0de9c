// The velocity–position correction against static boundaries: METHOD.md's step 7 (and its
// position rule inside the PCISPH loop) for a boundary that does not move and whose mass is
// infinite. Two shapes whose surfaces are known exactly: the domain walls and the static boxes.
//
// Why: a single Akinci layer repels a fluid particle less and less as it comes close to the layer
// (the layer's gradients cancel in its own plane), so a particle driven hard enough into a wall
// passes through it. Measured (fifteenth session): in scenes/dam_break_paper_kernel.json the
// returning wave presses a particle to 0.2 r0 from the back wall's layer at 3.7 m/s; its PCISPH
// prediction lands behind the layer, where the wall pushes it outward, and the step ends with it
// at 25 m/s through the wall (the 25 m/s "splash" and the one lost particle of the fourteenth
// session's runs).
//
// The rule: a fluid particle closer than `contact` to a boundary's first particle layer and
// moving towards it is put back at `contact` from the layer and keeps no velocity into it (the
// inelastic normal rule with m_k infinite: v̂ⁿ = vⁿ_k = 0). Tangential velocity is kept: the
// walls are free-slip (∂ = 1; friction is Eq. 8's job). Inside the PCISPH loop only the predicted
// position is corrected, so the density the pressure answers is never that of a particle behind
// the wall.
//
// `contact` is the paper's r0. For the domain walls it is never more than the distance at which
// fluid next to a face starts at rest (the gap plus r0/2: 1.1 r0 with one layer and h = 2 r0,
// 0.975 r0 with two), so a resting fluid block never starts inside the band. A static box's first
// layer lies on its faces and the scene builder keeps fluid kFluidClearance = r0 from it, so r0
// is right there as it is. Near a box's edges and corners the band is rounded (distance to the
// box, not to its faces' planes), so fluid flowing round an edge is not pushed off it.
#pragma once
#include <limits>

#include "algorithms/vec3.hpp"
#include "backend/view.hpp"

namespace mw {

// A static box's faces: its first boundary layer lies on them (sampling/box_particles.hpp).
struct ContactBox {
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
};

struct WallContact {
    static constexpr Real kFar = std::numeric_limits<Real>::max();
    // The planes the fluid may not cross moving outward: the wall layers moved in by `contact`.
    // Without domain walls they lie at the largest finite values, where no test passes, so that
    // the hot loops need no branch on whether there are walls.
    Vec3 lo{-kFar, -kFar, -kFar}, hi{kFar, kFar, kFar};
    // Static boxes (in backend memory), kept box_contact from.
    View<const ContactBox> boxes;
    Real box_contact = 0;

    // For a domain [domain_lo, domain_hi] whose walls' first layer lies `gap` outside the faces.
    static WallContact for_domain(Vec3 domain_lo, Vec3 domain_hi, Real gap, Real r0) {
        const Real rest = gap + r0 / 2;
        const Real contact = r0 < rest ? r0 : rest;
        const Real inward = contact - gap;  // from the face into the domain (negative: outside it)
        WallContact c;
        c.lo = Vec3{domain_lo.x + inward, domain_lo.y + inward, domain_lo.z + inward};
        c.hi = Vec3{domain_hi.x - inward, domain_hi.y - inward, domain_hi.z - inward};
        return c;
    }

    // After integration: the position back to the plane, the velocity into the wall removed.
    MW_INLINE void correct(Vec3& x, Vec3& v) const {
        axis(x.x, v.x, lo.x, hi.x);
        axis(x.y, v.y, lo.y, hi.y);
        axis(x.z, v.z, lo.z, hi.z);
        for (std::size_t b = 0; b < boxes.size(); ++b) box(x, v, boxes[b], box_contact);
    }

    // Inside PCISPH: the predicted position x* of a particle whose predicted velocity v* moves it
    // outward.
    MW_INLINE Vec3 correct_predicted(Vec3 x, Vec3 v) const {
        correct(x, v);
        return x;
    }

    // One static box: the nearest point q of the box to x; within `contact` of it and moving
    // towards it, x goes to q + contact n along n = (x - q)/|x - q| and v loses its part along
    // -n. A particle already inside the box (q = x) leaves through its nearest face.
    static MW_INLINE void box(Vec3& x, Vec3& v, const ContactBox& b, Real contact) {
        const Vec3 q{clamp(x.x, b.lo.x, b.hi.x), clamp(x.y, b.lo.y, b.hi.y), clamp(x.z, b.lo.z, b.hi.z)};
        const Vec3 d = x - q;
        const Real d2 = norm2(d);
        if (!(d2 < contact * contact)) return;  // the common case (and NaN: left to the guard)
        Vec3 n, surface = q;
        if (d2 > Real(0)) {
            n = (Real(1) / std::sqrt(d2)) * d;
        } else {
            // Inside: the face nearest to x, by axis and side.
            const Real depth[6] = {x.x - b.lo.x, b.hi.x - x.x, x.y - b.lo.y, b.hi.y - x.y, x.z - b.lo.z, b.hi.z - x.z};
            int face = 0;
            for (int f = 1; f < 6; ++f)
                if (depth[f] < depth[face]) face = f;
            const Real sign = (face & 1) ? Real(1) : Real(-1);
            const int axis_index = face >> 1;
            n = Vec3{axis_index == 0 ? sign : Real(0), axis_index == 1 ? sign : Real(0), axis_index == 2 ? sign : Real(0)};
            if (axis_index == 0) surface.x = (face & 1) ? b.hi.x : b.lo.x;
            if (axis_index == 1) surface.y = (face & 1) ? b.hi.y : b.lo.y;
            if (axis_index == 2) surface.z = (face & 1) ? b.hi.z : b.lo.z;
        }
        const Real vn = dot(v, n);
        if (!(vn < Real(0))) return;  // leaving the box
        x = surface + contact * n;
        v = v - vn * n;
    }

   private:
    static MW_INLINE Real clamp(Real x, Real lo_value, Real hi_value) {
        return x < lo_value ? lo_value : (x > hi_value ? hi_value : x);
    }
    // Selects, not branches: every fluid particle goes through this in the prediction and the
    // integration, and branches kept those loops from vectorizing (measured on the default dam
    // break, 300 steps, 2 threads: the integration stage took 0.33 ms with branches, 0.17 ms
    // with selects, 0.10 ms before the correction existed; PCISPH 12.4-12.8 ms with branches,
    // 11.7-12.3 either way with selects).
    static MW_INLINE void axis(Real& x, Real& v, Real lo_plane, Real hi_plane) {
        const bool below = x < lo_plane && v < Real(0);
        const bool above = x > hi_plane && v > Real(0);
        x = below ? lo_plane : (above ? hi_plane : x);
        v = (below || above) ? Real(0) : v;
    }
};

}  // namespace mw
