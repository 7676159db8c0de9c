// Mirror images across the domain's walls, for the viscosity next to them.
//
// The domain walls are free-slip planes (the faces of domain_min/domain_max). Eq. 4 sums over fluid
// neighbours, so a particle within h of a wall would miss the fluid beyond it and feel up to half
// the viscous stress it should. Beyond a free-slip plane the flow continues as its mirror image:
// positions reflected across the plane, the normal velocity component reversed, the tangential
// kept. For two particles inside the domain, a reflection only lengthens the normal component of
// x_i - x_j (both are on the same side of the face), so the image of j is within h of i only if j
// is: the images are found among i's own fluid neighbours. Near an edge or a corner, the images
// across two or three faces at once count too. (A fluid particle can stray a little past a face,
// up to the wall particles; the caller keeps only images of particles within h of i, so grid and
// lists give the same sums and every pair meets its image both ways.) On an axis narrower than h
// the images across both of its faces are not combined (periodic images of the slab): domains
// that thin are not a use case.
//
// A reflection is x' = offset + scale ⊙ x and v' = scale ⊙ v, with scale -1 and offset 2 p on each
// reflected axis (plane at p) and scale 1, offset 0 on the others.
#pragma once
#include "algorithms/vec3.hpp"

namespace mw {

struct WallMirrors {
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};  // the domain's faces
    unsigned faces = 0;             // bit 2a: the face at lo on axis a is a wall; bit 2a+1: at hi
    Real reach = 0;                 // h: images of particles farther than this from a face never count

    static constexpr unsigned kAllFaces = 0x3f;
    // The walls of a domain in `dimensions` (2: the four faces normal to x and y).
    static constexpr unsigned faces_in(int dimensions) { return dimensions == 2 ? 0x0fu : kAllFaces; }

    // Calls f(scale, offset) once for every reflection, across one face or several, whose images
    // can come within `reach` of x; nothing for a particle farther than `reach` from every wall.
    // Choices per axis: 0 keep, 1 reflect across the low face, 2 across the high one. No arrays
    // indexed at run time, so that on a GPU it all stays in registers.
    template <class F>
    MW_INLINE void for_each_reflection(Vec3 x, F&& f) const {
        if (!faces) return;
        const unsigned near_x = near_faces(x.x, lo.x, hi.x, faces);
        const unsigned near_y = near_faces(x.y, lo.y, hi.y, faces >> 2);
        const unsigned near_z = near_faces(x.z, lo.z, hi.z, faces >> 4);
        if (!(near_x | near_y | near_z)) return;  // the common case: no wall near
        for (int a = 0; a < 3; ++a) {
            if (a && !(near_x & (1u << (a - 1)))) continue;
            for (int b = 0; b < 3; ++b) {
                if (b && !(near_y & (1u << (b - 1)))) continue;
                for (int c = 0; c < 3; ++c) {
                    if (c && !(near_z & (1u << (c - 1)))) continue;
                    if (a + b + c == 0) continue;  // the particle itself, not an image
                    f(Vec3{scale(a), scale(b), scale(c)}, Vec3{offset(a, lo.x, hi.x), offset(b, lo.y, hi.y),
                                                               offset(c, lo.z, hi.z)});
                }
            }
        }
    }

   private:
    // Bit 0: the axis' low face is a wall within reach of x; bit 1: the high one.
    MW_INLINE unsigned near_faces(Real x, Real lo_face, Real hi_face, unsigned axis_faces) const {
        const unsigned near_lo = (axis_faces & 1u) && x - lo_face < reach ? 1u : 0u;
        const unsigned near_hi = (axis_faces & 2u) && hi_face - x < reach ? 2u : 0u;
        return near_lo | near_hi;
    }
    static MW_INLINE Real scale(int choice) { return choice ? Real(-1) : Real(1); }
    static MW_INLINE Real offset(int choice, Real lo_face, Real hi_face) {
        return choice == 1 ? 2 * lo_face : choice == 2 ? 2 * hi_face : Real(0);
    }
};

}  // namespace mw
