// Where the fluid meets an elastic or rigid object's surface particle (SBP): its face point
// x_s + inset_s n_s. The SBPs sit their inset inside the mesh's face (sampling/surface_inset.hpp)
// so that the density sees the object as it sees a wall; the velocity–position correction
// (virtual_boundary.hpp) and interface tension (interface_tension.hpp, coupling.hpp) act at the
// face itself.
#pragma once
#include <cstdint>

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
// as a face lined with its SBPs does, and the film between is squeezed out. 0: no fade (no walls).
inline Real surface_inset_fade(bool walls, Real support_radius, Real wall_gap) {
    return walls ? support_radius + (wall_gap > Real(0) ? wall_gap : Real(0)) : Real(0);
}

// How far an SBP with rest inset `inset` sits inside its face this step: scaled down linearly as
// its face point `face` comes within `fade` of a domain wall's face that its normal points at.
MW_INLINE Real faded_inset(Real inset, Vec3 face, Vec3 normal, Vec3 lo, Vec3 hi, Real fade) {
    if (!(inset > Real(0)) || !(fade > Real(0))) return inset;
    Real gap = fade;
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
