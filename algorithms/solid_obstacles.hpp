// What a moving solid's particles meet besides the domain walls: the static boxes and the static
// mesh objects (docs/contact.md). An IBP is a contact when it lies closer than its object's margin
// to an obstacle's surface, or inside it: r0/2 from a mesh object (a lattice's outer IBPs lie about
// r0/2 inside its surface), and from a box as from the domain walls (r0/2, or 2 r0 where the
// object keeps the walls' film: lsm_regions.hpp, wall_margin); its depth is how far it must move
// along the obstacle's outward normal to lie at the margin. The geometry is the walls' correction's (wall_contact.hpp):
// a box's faces (its first particle layer lies on them), a mesh object's signed distance grid.
// lsm.hpp answers the contacts: IBP by IBP for an elastic object or cloth, as one body for a rigid
// object.
#pragma once
#include <cmath>

#include "algorithms/wall_contact.hpp"

namespace mw {

// Sweeps of the Jacobi solve between solids a substep (solid_collisions.hpp): a stack of two
// rigid boxes stands at 32 and creeps at 16 (docs/contact.md).
constexpr int kCollisionIterations = 32;

struct SolidObstacles {
    View<const ContactBox> boxes;       // lo, hi (their `contact` is the fluid's, unused here)
    View<const ContactField> objects;   // field (its `contact` unused here)
    View<const Real> object_distances;  // every object's grid values, one after another
    // The domain walls, for the contacts between solids (solid_collisions.hpp), which answer them
    // with the rest; deepest() leaves them out (lsm.hpp meets them apart).
    bool walls = false;
    Vec3 wall_lo{0, 0, 0}, wall_hi{0, 0, 0};  // the domain's faces

    MW_INLINE bool any() const { return boxes.size() + objects.size() != 0; }

    // deepest() with the domain walls, met at `margin` as the boxes are.
    MW_INLINE bool deepest_with_walls(Vec3 x, Real margin, Real object_margin, Vec3& n, Real& depth) const {
        if (!deepest(x, margin, object_margin, n, depth)) depth = Real(0);
        if (!walls || !is_finite(x)) return depth > Real(0);
        const Real past[6] = {wall_lo.x + margin - x.x, x.x - (wall_hi.x - margin), wall_lo.y + margin - x.y,
                              x.y - (wall_hi.y - margin), wall_lo.z + margin - x.z, x.z - (wall_hi.z - margin)};
        for (int f = 0; f < 6; ++f) {
            if (!(past[f] > depth)) continue;
            depth = past[f];
            n = -box_face_normal(f);  // into the domain
        }
        return depth > Real(0);
    }

    // The deepest contact of a particle at x kept `margin` off every static box and
    // `object_margin` off every mesh object: true, with the unit outward normal n and depth > 0,
    // when there is one. A particle inside a box leaves through
    // its nearest face; inside a mesh object, along the distance's gradient (a flat gradient, in
    // a plate thinner than the grid resolves, gives no direction and no contact). Non-finite x:
    // none (the guard's).
    MW_INLINE bool deepest(Vec3 x, Real margin, Real object_margin, Vec3& n, Real& depth) const {
        if (!is_finite(x)) return false;
        depth = Real(0);
        for (std::size_t b = 0; b < boxes.size(); ++b) {
            Vec3 nb;
            const Real db = box_depth(x, margin, boxes[b], nb);
            if (db > depth) depth = db, n = nb;
        }
        for (std::size_t o = 0; o < objects.size(); ++o) {
            Real distance = 0;
            Vec3 gradient{0, 0, 0};
            if (!objects[o].field.sample(object_distances, x, distance, gradient) || !(distance < object_margin)) continue;
            const Real g2 = norm2(gradient);
            if (!(g2 > Real(1e-6))) continue;
            if (object_margin - distance > depth) depth = object_margin - distance, n = (Real(1) / std::sqrt(g2)) * gradient;
        }
        return depth > Real(0);
    }

    // How far x lies inside the box grown by `margin` (rounded at its edges and corners), and the
    // way out; 0 when outside.
    static MW_INLINE Real box_depth(Vec3 x, Real margin, const ContactBox& b, Vec3& n) {
        const Vec3 q{x.x < b.lo.x ? b.lo.x : (x.x > b.hi.x ? b.hi.x : x.x),
                     x.y < b.lo.y ? b.lo.y : (x.y > b.hi.y ? b.hi.y : x.y),
                     x.z < b.lo.z ? b.lo.z : (x.z > b.hi.z ? b.hi.z : x.z)};
        const Vec3 d = x - q;
        const Real d2 = norm2(d);
        if (!(d2 < margin * margin)) return Real(0);
        if (d2 > Real(0)) {
            const Real distance = std::sqrt(d2);
            n = (Real(1) / distance) * d;
            return margin - distance;
        }
        Real inside = 0;
        n = box_face_normal(nearest_inner_face(x, b.lo, b.hi, inside));
        return margin + inside;
    }
};

}  // namespace mw
