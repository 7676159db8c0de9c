// Where the fluid meets an elastic or rigid object's surface particle (SBP): its face point
// x_s + inset_s n_s. The SBPs sit their inset inside the mesh's face (sampling/surface_inset.hpp)
// so that the density sees the object as it sees a wall; the velocity–position correction
// (virtual_boundary.hpp) and interface tension (interface_tension.hpp, coupling.hpp) act at the
// face itself.
#pragma once
#include <cstddef>
#include <cstdint>
#include <limits>

#include "algorithms/vec3.hpp"

namespace mw {

struct SbpFaces {
    const Vec3* normal = nullptr;  // by SBP index, unit, outward
    const Real* inset = nullptr;   // by SBP index, m; null: every SBP on its face
    MW_INLINE Vec3 at(Vec3 xs, std::uint32_t s) const { return inset ? xs + inset[s] * normal[s] : xs; }
};

// Near a domain wall the SBPs return to the face. A fluid particle between a face and a wall
// feels both the SBPs and the wall's layer once the face is within h of that layer (h + the
// walls' gap of the wall's face); set in all the way, the SBPs and the wall's layer would hold
// one fluid layer at rest density under a body resting on the floor, and a heavy body landing
// on it is thrown back (docs/coupling.md). Faded out over that length, the face meets the wall
// as a face lined with its SBPs does, and the film between is squeezed out. A static box's faces
// are met the same way (facing_box_gap). The fade: h plus the widest layer gap of the walls and
// the boxes; 0 with neither.
template <class Boxes>
inline Real surface_inset_fade(bool walls, Real support_radius, Real wall_gap, const Boxes& boxes) {
    Real gap = walls && wall_gap > Real(0) ? wall_gap : Real(0);
    for (const auto& b : boxes) gap = b.layer_gap > gap ? b.layer_gap : gap;
    return walls || !boxes.empty() ? support_radius + gap : Real(0);
}

// The domain's faces as the fade sees them: none without walls (a fade that only static boxes
// need leaves the open domain's faces alone).
inline void faces_to_fade_at(bool walls, Vec3 domain_min, Vec3 domain_max, Vec3& lo, Vec3& hi) {
    const Real far = std::numeric_limits<Real>::max();
    lo = walls ? domain_min : Vec3{-far, -far, -far};
    hi = walls ? domain_max : Vec3{far, far, far};
}

// How far a face point lies from a static box's face [lo, hi] that its normal points at, when it
// lies over that face (within the box's extent along the other two axes) and nearer than `gap`;
// otherwise `gap`. Its top under a body resting on it is such a face, as the floor is.
MW_INLINE Real facing_box_gap(Vec3 face, Vec3 normal, Vec3 lo, Vec3 hi, Real gap) {
    const Real f[3] = {face.x, face.y, face.z}, n[3] = {normal.x, normal.y, normal.z};
    const Real l[3] = {lo.x, lo.y, lo.z}, h[3] = {hi.x, hi.y, hi.z};
    const Real half = Real(0.5);
    for (int k = 0; k < 3; ++k) {
        const int a = (k + 1) % 3, c = (k + 2) % 3;
        if (f[a] < l[a] || f[a] > h[a] || f[c] < l[c] || f[c] > h[c]) continue;
        if (n[k] < -half && f[k] >= h[k] && f[k] - h[k] < gap) gap = f[k] - h[k];
        if (n[k] > half && f[k] <= l[k] && l[k] - f[k] < gap) gap = l[k] - f[k];
    }
    return gap;
}

// How far an SBP with rest inset `inset` sits inside its face this step: scaled down linearly as
// its face point `face` comes within `fade` of a domain wall's face that its normal points at.
// And as it comes within `fade` of a static box's face it points at (`boxes`: anything with
// size() and [k].lo, [k].hi).
template <class Boxes>
MW_INLINE Real faded_inset(Real inset, Vec3 face, Vec3 normal, Vec3 lo, Vec3 hi, Real fade, const Boxes& boxes) {
    if (!(inset > Real(0)) || !(fade > Real(0))) return inset;
    Real gap = fade;
    for (std::size_t b = 0; b < boxes.size(); ++b) gap = facing_box_gap(face, normal, boxes[b].lo, boxes[b].hi, gap);
    const Real half = Real(0.5);
    if (normal.x < -half && face.x - lo.x < gap) gap = face.x - lo.x;
    if (normal.x > half && hi.x - face.x < gap) gap = hi.x - face.x;
    if (normal.y < -half && face.y - lo.y < gap) gap = face.y - lo.y;
    if (normal.y > half && hi.y - face.y < gap) gap = hi.y - face.y;
    if (normal.z < -half && face.z - lo.z < gap) gap = face.z - lo.z;
    if (normal.z > half && hi.z - face.z < gap) gap = hi.z - face.z;
    return gap > Real(0) ? inset * (gap / fade) : Real(0);
}

// How the fluid meets an SBP (its normal in the velocity–position correction): from outside the
// face (volumes); from either side of a sheet (cloth: the normal turns toward the side the fluid
// particle comes from); from any direction around a line (rods: the SBP's stored vector is the
// line's tangent, and the normal is the part of x_i - x_s across it).
enum SbpSides : std::uint8_t { kSbpOneSided = 0, kSbpTwoSided = 1, kSbpAround = 2 };

// The normal SBP s shows a fluid particle that started the step at `from`: `stored` is its
// normal (its tangent for kSbpAround), `to_fluid` = from - x_s. Zero where it has no direction
// (a particle on the line itself).
MW_INLINE Vec3 sbp_normal_toward(Vec3 stored, std::uint8_t sides, Vec3 to_fluid) {
    if (sides == kSbpTwoSided) return dot(stored, to_fluid) < Real(0) ? Real(-1) * stored : stored;
    if (sides != kSbpAround) return stored;
    Vec3 across = to_fluid - dot(to_fluid, stored) * stored;
    Real length = norm(across);
    // Off the end of the line, straight along it: the direction to the particle.
    if (!(length > Real(1e-3) * norm(to_fluid))) {
        across = to_fluid;
        length = norm(across);
    }
    return length > Real(0) ? (Real(1) / length) * across : Vec3{0, 0, 0};
}

}  // namespace mw
