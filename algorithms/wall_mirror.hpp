// Mirror images across the domain's walls, for the viscosity next to them.
//
// The domain walls are free-slip planes (the faces of domain_min/domain_max). Eq. 4 sums over fluid
// neighbours, so a particle within h of a wall would miss the fluid beyond it and feel up to half
// the viscous stress it should. Beyond a free-slip plane the flow continues as its mirror image:
// positions reflected across the plane, the normal velocity component reversed, the tangential
// kept. A ghost of fluid particle j across a face is within h of particle i only if j is (the
// reflection only lengthens the normal component of x_i - x_j, both being on the same side), so
// the ghosts are found among i's own fluid neighbours. Near an edge or a corner, the images across
// two or three faces at once count too.
//
// A reflection is x' = offset + scale ⊙ x and v' = scale ⊙ v, with scale -1 and offset 2 p on each
// reflected axis (plane at p) and scale 1, offset 0 on the others.
#pragma once
#include "algorithms/vec3.hpp"

namespace mw {

MW_INLINE Vec3 hadamard(Vec3 a, Vec3 b) { return Vec3{a.x * b.x, a.y * b.y, a.z * b.z}; }

struct WallMirrors {
    Vec3 lo{0, 0, 0}, hi{0, 0, 0};  // the domain's faces
    unsigned faces = 0;             // bit 2a: the face at lo on axis a is a wall; bit 2a+1: at hi
    Real reach = 0;                 // h: images of particles farther than this from a face never count

    static constexpr unsigned kAllFaces = 0x3f;

    // Calls f(scale, offset) once for every reflection, across one face or several, whose images
    // can come within `reach` of x; nothing for a particle farther than `reach` from every wall.
    template <class F>
    MW_INLINE void for_each_reflection(Vec3 x, F&& f) const {
        if (!faces) return;
        Axis ax, ay, az;
        ax.add(x.x, lo.x, hi.x, faces, reach);
        ay.add(x.y, lo.y, hi.y, faces >> 2, reach);
        az.add(x.z, lo.z, hi.z, faces >> 4, reach);
        if (ax.count + ay.count + az.count == 3) return;  // the common case: no wall near
        for (int a = 0; a < ax.count; ++a)
            for (int b = 0; b < ay.count; ++b)
                for (int c = 0; c < az.count; ++c)
                    if (a + b + c > 0)
                        f(Vec3{ax.scale[a], ay.scale[b], az.scale[c]}, Vec3{ax.offset[a], ay.offset[b], az.offset[c]});
    }

   private:
    // The choices on one axis: keep (always), reflect across the low face, across the high face.
    struct Axis {
        int count = 1;
        Real scale[3] = {1, 1, 1};
        Real offset[3] = {0, 0, 0};
        MW_INLINE void add(Real x, Real lo_face, Real hi_face, unsigned axis_faces, Real reach) {
            if ((axis_faces & 1u) && x - lo_face < reach) {
                scale[count] = -1;
                offset[count++] = 2 * lo_face;
            }
            if ((axis_faces & 2u) && hi_face - x < reach) {
                scale[count] = -1;
                offset[count++] = 2 * hi_face;
            }
        }
    };
};

}  // namespace mw
