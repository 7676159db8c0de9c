// The velocity–position correction against static boundaries (docs/method.md, "The
// velocity–position correction"), and its position rule inside the PCISPH loop, for a boundary
// that does not move and whose mass is infinite. Three kinds of static boundary whose surfaces are
// known exactly: the domain walls, the static boxes, and static mesh objects through their signed
// distance grids (distance_field.hpp, sampling/signed_distance.hpp).
//
// Why: a single Akinci layer repels a fluid particle less and less as it comes close to the layer
// (the layer's gradients cancel in its own plane), so a particle driven hard enough into a wall
// passes through it. Without the correction, in scenes/dam_break_paper_kernel.json the returning
// wave presses a particle to 0.2 r0 from the back wall's layer at 3.7 m/s; its PCISPH prediction
// lands behind the layer, where the wall pushes it outward, and the step ends with it at 25 m/s
// through the wall (docs/solver.md).
//
// The rule: a fluid particle closer than `contact` to a boundary's first particle layer and
// moving towards it is put back at `contact` from the layer and keeps no velocity into it (the
// inelastic normal rule with m_k infinite: v̂ⁿ = vⁿ_k = 0). Tangential velocity is kept: the
// walls are free-slip (∂ = 1; friction is Eq. 8's job). Inside the PCISPH loop only the predicted
// position is corrected, so the density the pressure answers is never that of a particle behind
// the wall.
//
// The distance: the paper's r0, but always at least 0.1 r0 short of where the fluid next to the
// boundary rests (its rest distance less 0.1 r0, the slack the default walls have: one layer at
// h = 2 r0 rests at 1.1 r0), so resting fluid is not held on the band's edge by rounding and
// hydrostatic compression. Domain walls: the rest distance is the gap plus r0/2 (fluid blocks
// start r0/2 inside the faces), so the band is r0 for one layer and 0.875 r0 for two. Static
// boxes: their first layer lies on their faces, so the rest distance is the same for the same
// layers, and the band is also kept inside the distance at which the scene builder's carve can
// leave fluid (carved_face_distance(), sampling/fluid_clearance.hpp; contact_box() below sets each
// box's band from what the scene builder passes). Near a box's edges and corners the band is rounded (the
// distance to the box, not to its faces' planes), so fluid flowing round an edge is not pushed
// off it. Static mesh objects: the same rule on their signed distance, with the normal its
// gradient (so rounded at edges and corners as well); a particle found inside leaves through the
// nearest surface. Their band is narrower, kStaticObjectContact r0 from the surface: fluid rests
// closer to an object's particles (its surface particles lie on the surface 0.5 r0 apart, its
// inner lattice behind them) than to a wall's layer. Measured (h = 2 r0, cubic spline, a box
// object in pools 0.4 and 0.9 m deep): 0.65-0.75 r0 from its faces, down to 0.54 r0 by its edges;
// the band stays 0.1 r0 short of that, and the 0.4 m pool settles bitwise the same with it as
// without it (docs/solver.md, "The walls' velocity–position correction").
#pragma once
#include <limits>

#include "algorithms/distance_field.hpp"
#include "algorithms/vec3.hpp"
#include "backend/view.hpp"

namespace mw {

// For x inside the box [lo, hi]: the face it is nearest to, 2 axis + 1 for the high side, and its
// distance from it.
MW_INLINE int nearest_inner_face(Vec3 x, Vec3 lo, Vec3 hi, Real& distance) {
    const Real depth[6] = {x.x - lo.x, hi.x - x.x, x.y - lo.y, hi.y - x.y, x.z - lo.z, hi.z - x.z};
    int face = 0;
    for (int f = 1; f < 6; ++f)
        if (depth[f] < depth[face]) face = f;
    distance = depth[face];
    return face;
}
// That face's outward unit normal.
MW_INLINE Vec3 box_face_normal(int face) {
    const Real sign = (face & 1) ? Real(1) : Real(-1);
    const int axis = face >> 1;
    return Vec3{axis == 0 ? sign : Real(0), axis == 1 ? sign : Real(0), axis == 2 ? sign : Real(0)};
}

// A static box's faces (its first boundary layer lies on them, sampling/box_particles.hpp), and
// how far from the box fluid moving into it is stopped.
struct ContactBox {
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
    Real contact = 0;
};

// The band's width for a boundary whose first layer lies `gap` (sampling/wall_gap.hpp) from
// where fluid blocks start, r0/2 outside the fluid: that fluid rests gap + r0/2 from the layer,
// and the band is r0, at most that less 0.1 r0.
inline Real contact_distance(Real gap, Real r0) {
    const Real short_of_rest = gap + r0 / 2 - Real(0.1) * r0;
    return r0 < short_of_rest ? r0 : short_of_rest;
}

// A static box as the scene builder places it: its faces, how far its first boundary layer lies
// from where fluid blocks start (sampling/wall_gap.hpp), and the closest a fluid particle kept by
// the carve starts to a face (sampling/fluid_clearance.hpp). The walls' correction turns it into a
// ContactBox.
struct StaticBoxFaces {
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};
    Real layer_gap = 0;
    Real carve_distance = 0;
};

// In 2D a box [lo, hi] is a rectangle in the plane: it has no face normal to z, so its extent
// along z is made unbounded (every test on z then passes).
inline void open_along_z_in_2d(Vec3& lo, Vec3& hi, int dimensions) {
    if (dimensions != 2) return;
    lo.z = -std::numeric_limits<Real>::infinity();
    hi.z = std::numeric_limits<Real>::infinity();
}

// The band of a static box: as a wall's, and no wider than the carve lets fluid start.
inline ContactBox contact_box(const StaticBoxFaces& box, Real r0, int dimensions = 3) {
    const Real band = contact_distance(box.layer_gap, r0);
    ContactBox c{box.lo, box.hi, band < box.carve_distance ? band : box.carve_distance};
    open_along_z_in_2d(c.lo, c.hi, dimensions);
    return c;
}

// A static mesh object's signed distance (values in backend memory), and how far from its surface
// fluid moving into it is stopped.
struct ContactField {
    DistanceField field;
    Real contact = 0;
};

// The band of static mesh objects, in r0 (see the header comment).
constexpr double kStaticObjectContact = 0.45;
// The band of moving (elastic and rigid) objects, in r0, for their own correction
// (solid_contact.hpp): as static mesh objects', which are sampled the same way.
constexpr double kMovingSolidContact = kStaticObjectContact;
// The band of moving objects whose SBPs sit inside their face (sampling/surface_inset.hpp),
// measured from the face: fluid rests a median 0.34-0.40 r0 off it, where a band of 0.45 r0
// moves resting fluid every step (docs/coupling.md).
constexpr double kInsetSolidContact = 0.3;
// The band against the moving objects' SBPs, in r0: one for the whole scene, the narrower one
// when any SBP sits inside its face or a melting lattice's faces are met, r0/2 in front of its
// vertices (SimulationSetup::narrow_solid_band; SolidBodies::surface_inset and lattice_faces_met
// on the device side), so that `meltwater info` and the correction agree.
constexpr double moving_solid_contact(bool any_sbp_set_in) {
    return any_sbp_set_in ? kInsetSolidContact : kMovingSolidContact;
}

struct WallContact {
    static constexpr Real kFar = std::numeric_limits<Real>::max();
    // The planes the fluid may not cross moving outward: the wall layers moved in by `contact`.
    // Without domain walls they lie at the largest finite values, where no test passes, so that
    // the hot loops need no branch on whether there are walls.
    Vec3 lo{-kFar, -kFar, -kFar}, hi{kFar, kFar, kFar};
    // Static boxes and static mesh objects (in backend memory).
    View<const ContactBox> boxes;
    View<const ContactField> objects;
    View<const Real> object_distances;  // every object's grid values, one after another

    // For a domain [domain_lo, domain_hi] whose walls' first layer lies `gap` outside the faces.
    static WallContact for_domain(Vec3 domain_lo, Vec3 domain_hi, Real gap, Real r0, int dimensions = 3) {
        const Real contact = contact_distance(gap, r0);
        const Real inward = contact - gap;  // from the face into the domain (negative: outside it)
        WallContact c;
        c.lo = Vec3{domain_lo.x + inward, domain_lo.y + inward, domain_lo.z + inward};
        c.hi = Vec3{domain_hi.x - inward, domain_hi.y - inward, domain_hi.z - inward};
        open_along_z_in_2d(c.lo, c.hi, dimensions);
        return c;
    }

    // After integration: the position back to the band's edge, the velocity into the boundary
    // removed. Objects and boxes first, the walls last: a particle pushed out of a box that stands
    // on the floor must not end up beyond the floor's layer. Non-finite values are left to the
    // guard.
    // Always inlined, with the shapes' loops in a function apart: with the objects' loop inline,
    // g++ reorders the walls' tests and then calls this out of line (callgrind, 10 steps of the
    // default dam break, 1 thread: 160M instructions in the predictions, the integration and the
    // calls; 119M as written, against 111M with no loop over shapes at all).
    MW_ALWAYS_INLINE void correct(Vec3& x, Vec3& v) const {
        if (objects.size() + boxes.size() != 0) correct_shapes(x, v);
        axis(x.x, v.x, lo.x, hi.x);
        axis(x.y, v.y, lo.y, hi.y);
        axis(x.z, v.z, lo.z, hi.z);
    }

    // The static objects' and boxes' part of correct().
    MW_INLINE void correct_shapes(Vec3& x, Vec3& v) const {
        for (std::size_t o = 0; o < objects.size(); ++o) object(x, v, objects[o], object_distances);
        for (std::size_t b = 0; b < boxes.size(); ++b) box(x, v, boxes[b]);
    }

    // Inside PCISPH: the predicted position x* of a particle whose predicted velocity v* moves it
    // outward.
    MW_ALWAYS_INLINE Vec3 correct_predicted(Vec3 x, Vec3 v) const {
        correct(x, v);
        return x;
    }

    // One static box: the nearest point q of the box to x; within `contact` of it and moving
    // towards it, x goes to q + contact n along n = (x - q)/|x - q| and v loses its part along
    // -n. A particle inside the box (q = x), which is never right, leaves through its nearest
    // face whichever way it moves, losing any velocity into that face.
    static MW_INLINE void box(Vec3& x, Vec3& v, const ContactBox& b) {
        const Vec3 q{clamp(x.x, b.lo.x, b.hi.x), clamp(x.y, b.lo.y, b.hi.y), clamp(x.z, b.lo.z, b.hi.z)};
        const Vec3 d = x - q;
        const Real d2 = norm2(d);
        if (!(d2 < b.contact * b.contact) || !is_finite(x) || !is_finite(v)) return;  // the common case
        Vec3 n, surface = q;
        const bool inside = !(d2 > Real(0));
        if (!inside) {
            n = (Real(1) / std::sqrt(d2)) * d;
        } else {
            Real inside = 0;
            const int face = nearest_inner_face(x, b.lo, b.hi, inside);
            const int axis_index = face >> 1;
            n = box_face_normal(face);
            if (axis_index == 0) surface.x = (face & 1) ? b.hi.x : b.lo.x;
            if (axis_index == 1) surface.y = (face & 1) ? b.hi.y : b.lo.y;
            if (axis_index == 2) surface.z = (face & 1) ? b.hi.z : b.lo.z;
        }
        const Real vn = dot(v, n);
        if (!inside && !(vn < Real(0))) return;  // in the band but leaving the box
        x = surface + b.contact * n;
        if (vn < Real(0)) v = v - vn * n;
    }

    // One static mesh object: within `contact` of its surface (by its signed distance d) and
    // moving towards it, or inside it (d < 0) whichever way it moves, x moves along the unit
    // gradient n to where d is `contact`, and v loses its part along -n. Outside the object's grid
    // the distance is more than the band (the grid reaches past it), so nothing happens there.
    // The grid's nodes hold exact distances, but between them the interpolation overestimates the
    // distance near a convex edge or corner (it is convex there), so the band is thinner there:
    // measured on a box at r0/2 spacing, particles are stopped 0.38-0.42 r0 from an edge and
    // 0.33-0.40 r0 from a corner for a band of 0.45 r0 (0.45 r0 from a face).
    static MW_INLINE void object(Vec3& x, Vec3& v, const ContactField& c, View<const Real> distances) {
        Real d = 0;
        Vec3 gradient{0, 0, 0};
        if (!c.field.sample(distances, x, d, gradient) || !(d < c.contact) || !is_finite(v)) return;
        Vec3 n{0, 0, 0};
        if (!way_out(gradient, v, n)) return;
        const Real vn = dot(v, n);
        if (!(d < Real(0)) && !(vn < Real(0))) return;  // in the band but leaving the object
        x = x + (c.contact - d) * n;
        if (vn < Real(0)) v = v - vn * n;
    }

    // The unit direction out of an object: along the distance's gradient; where the field is flat
    // (the middle of a plate thinner than a few grid cells, which the interpolation cannot see
    // across), back the way the particle came. False when there is neither.
    static MW_INLINE bool way_out(Vec3 gradient, Vec3 v, Vec3& n) {
        const Real g2 = norm2(gradient);
        if (g2 > Real(1e-6)) {
            n = (Real(1) / std::sqrt(g2)) * gradient;
            return true;
        }
        const Real v2 = norm2(v);
        if (!(v2 > Real(0))) return false;
        n = -(Real(1) / std::sqrt(v2)) * v;
        return true;
    }

   private:
    static MW_INLINE Real clamp(Real x, Real lo_value, Real hi_value) {
        return x < lo_value ? lo_value : (x > hi_value ? hi_value : x);
    }
    // Every fluid particle goes through this in the prediction and the integration: one
    // predictable test first (between the planes, nothing to do), then selects. Fully branched
    // code makes those loops slow (default dam break, 300 steps, 2 threads: the integration takes
    // 0.33 ms with branches, 0.17 ms with selects).
    static MW_ALWAYS_INLINE void axis(Real& x, Real& v, Real lo_plane, Real hi_plane) {
        // -kFar <= x and v <= kFar keep an infinite position or velocity for the guard (NaN fails
        // every test by itself).
        if (!(x < lo_plane || x > hi_plane)) return;  // between the planes: nearly every particle
        const bool below = x < lo_plane && v < Real(0) && x >= -kFar && v >= -kFar;
        const bool above = x > hi_plane && v > Real(0) && x <= kFar && v <= kFar;
        x = below ? lo_plane : (above ? hi_plane : x);
        v = (below || above) ? Real(0) : v;
    }
};

}  // namespace mw
