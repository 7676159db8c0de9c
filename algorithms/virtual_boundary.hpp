// The virtual boundary particle of the velocity–position correction against moving solids (the
// paper's Eq. 11; docs/method.md): what a fluid particle collides with when it comes too close
// to an elastic or rigid object's surface particles (SBPs). Read by the correction after the
// integration (solid_contact.hpp) and by its position rule inside the PCISPH loop (pcisph.hpp).
//
//   x_s   = SBP s's face point (solid_face.hpp): where the mesh's face is, the SBP itself sitting
//           its inset inside it (sampling/surface_inset.hpp)
//   S     = the SBPs s with |x_i - x_s| < r0
//   w_s   = (1 - |x_i - x_s| / r0)³ (the paper's W(x, r0), from [YLHQ12])
//   x_k, v_k, n_k = the w-weighted means over S (n_k normalised); 1/m_k the w-weighted mean of
//           the SBPs' inverse contact masses (0: infinitely heavy)
//   the particle collides when it lies within the band c of k's surface (below) and moves into
//   it: (v_i - v_k)·n_k < 0
// The paper weights by m_s w_s; weighting by w_s alone keeps infinitely heavy SBPs (one-way
// coupling, pinned lattice) finite, and the contact masses of one object's SBPs differ little.
//
// The paper builds k from P, the SBPs of S that the particle moves into ((v_i - v_s)·n_s < 0).
// Built from P, k goes wrong at a box's edge: the SBPs along an edge belong to one of its two
// faces, and a fluid particle resting beside the other face, moving into a few of the first
// face's edge SBPs (up to r0 away, weights down to 1e-6) but not into its own face's, gets a k
// on the first face's plane, which, extended past the edge, puts it up to 1.1 r0 "inside": the
// correction pushes it 0.4-1.1 r0 along the wrong face, and the pool of scenes/floating_boxes.json
// runs at up to 4.5 m/s with the correction against 1.0 m/s without it. Built from S, k
// describes the surface as the density sees it, and the pool runs as calm with the correction as
// without it. The cost, in fluid thrown at a cube at 4-6 times the CFL step: more particles get
// in than with P (docs/coupling.md).
//
// A melting object's exposed lattice vertices (IBP slots with the SBP type) count in S as SBPs do,
// each standing for its cell's face r0/2 in front of it along the normal melting_faces.hpp reads
// from the lattice, or for the vertex itself, met from all round, where it has no outside. A
// virtual particle with lattice faces in it whose normals sum to less than kOpposedFaces of their
// weight lies between two faces that look at each other: none.
//
// k's surface is a disc of radius kSurfacePatchRadius r0 round x_k in k's plane: a particle
// beside the disc (past an edge of the object, where S holds only the SBPs nearest the edge) is
// as far from the surface as from the disc's rim, not as far as from the plane.
//
// The correction acts only within the band c of that surface (wall_contact.hpp): with the SBPs
// set in (a rigid object's), kInsetSolidContact r0 (fluid at rest lies a median 0.34-0.40 r0 off
// the face); in a scene with none set in, kMovingSolidContact r0 (fluid at rest lies 0.65-0.8 r0
// from SBPs on the face, which a band of r0 would hold on its edge, as it would at the walls with
// a band of r0). The band is the scene's (SolidCorrection): beside a rigid object set in, an
// elastic object's SBPs are met with the narrower band too. The test radius stays r0, so that fluid up to r0 inside the surface is
// still found and put back.
#pragma once
#include <cmath>
#include <cstdint>

#include "algorithms/neighbor_grid.hpp"
#include "algorithms/particle_types.hpp"
#include "algorithms/solid_face.hpp"

namespace mw {

// w_s when fluid particle x is within `reach` of SBP s, else 0: one expression wherever it is
// evaluated (the fluid's gather and the SBPs' must agree to the bit).
MW_INLINE Real contact_weight(Vec3 x, Vec3 xs, Real reach) {
    const Real d2 = norm2(x - xs);
    if (!(d2 < reach * reach)) return Real(0);
    const Real t = Real(1) - std::sqrt(d2) / reach;
    return t * t * t;
}

// The radius of the virtual particle's surface, in r0: the least distance between two SBPs
// (sampling/surface_sampler.hpp). Measured on scenes/floating_boxes.json to t = 1 s (top fluid
// speed; 1.02 m/s without the correction): 1.22 m/s at r0/2, and 3.51 m/s with the plane alone.
constexpr double kSurfacePatchRadius = 0.5;
// A virtual particle built from melting lattices' faces whose weighted normals sum to less than
// this share of their weight is between opposed faces: none.
constexpr double kOpposedFaces = 0.5;

struct VirtualBoundary {
    Real weight = 0;  // Σ w_s; 0: no SBP within r0
    Vec3 position{0, 0, 0}, velocity{0, 0, 0}, normal{0, 0, 0};
    Real inverse_mass = 0;
    MW_INLINE bool found() const { return weight > Real(0); }

    // How far x lies in front of the disc of radius `patch` round `position` (negative: behind
    // its plane, within the disc's radius of `position`).
    MW_INLINE Real depth(Vec3 x, Real patch) const {
        const Vec3 d = x - position;
        const Real in_front = dot(d, normal);
        const Real beside = norm(d - in_front * normal) - patch;
        return beside > Real(0) ? std::sqrt(in_front * in_front + beside * beside) : in_front;
    }
    // Whether fluid at velocity v moves into it.
    MW_INLINE bool approached_by(Vec3 v) const { return dot(v - velocity, normal) < Real(0); }
};

}  // namespace mw

MW_BACKEND_BEGIN

// The moving solids' surface as the fluid sees it. Default-constructed: none (no gather).
struct SolidSurface {
    GridView grid;
    View<const std::uint8_t> type;  // store fields
    View<const std::int32_t> solid_slot;
    const Vec3* sbp_normal = nullptr;  // by SBP index; null: no correction against solids
    const Real* sbp_inset = nullptr;   // by SBP index (solid_face.hpp); null: on the face
    // By SBP index, how the fluid meets it (solid_face.hpp, SbpSides: a cloth's from both sides, a
    // rod's from all round); null: every SBP from outside its face. Its normal turns toward where
    // the fluid particle comes from (`from` of collide).
    const std::uint8_t* sbp_sides = nullptr;
    // By SBP index, the inverse contact masses (solid_contact.hpp); null: every SBP infinitely
    // heavy (one-way coupling).
    const Real* sbp_inverse_mass = nullptr;
    // A melting object's exposed lattice vertices (IBP slots with the SBP type; melting_faces.hpp),
    // by IBP slot: the outward normal, zero where the fluid meets the vertex from all round (one
    // with vertices left on opposite sides: a one-layer sheet or a lone vertex), and the inverse
    // contact mass (two-way). Null: a scene with no melting object, or the correction off.
    const Vec3* lattice_normal = nullptr;
    const Real* lattice_inverse_mass = nullptr;
    Real lattice_inset = 0;  // m: a vertex's face lies this far in front of it (r0/2: its cell's face)
    std::uint32_t ibp_count = 0, sbp_count = 0;  // SBP k has solid slot ibp_count + k
    Real band = 0;   // c, m
    Real reach = 0;  // r0, m
    // reach plus the largest inset: an SBP farther than this from a fluid particle has its face
    // point out of reach too, and is passed over without reading its normal and inset.
    Real sbp_reach = 0;
    // Per fluid particle, this step: whether a moving solid's particle lies in the cells its
    // gather visits (mark_fluid_near_solids); null: gather for every particle. Far from the
    // solids, as most fluid is, the rule then costs one byte read per prediction, not a gather.
    const std::uint8_t* fluid_near_solid = nullptr;

    MW_INLINE bool active() const { return sbp_normal != nullptr || lattice_normal != nullptr; }
    MW_INLINE SbpFaces faces() const { return SbpFaces{sbp_normal, sbp_inset}; }
    // Where a melting lattice's exposed vertex at x, IBP slot s, meets the fluid: its cell's face
    // in front of it, or the vertex itself where it has no outside (melting_faces.hpp).
    MW_INLINE Vec3 lattice_face(Vec3 x, std::uint32_t s) const { return x + lattice_inset * lattice_normal[s]; }

    // The virtual particle fluid particle i at x faces: a gather over the SBPs around the cell i
    // was sorted into at this step's build (neighbor_grid.hpp), from the store's positions and
    // velocities. A virtual particle whose normals cancel is none. `from`: where i was at the
    // start of the step, which decides the side of a two-sided SBP it meets and the direction
    // round a rod's. The paper turns a cloth's normal along x_is = x_i - x_s; a particle that has
    // already crossed the sheet in this step would then be pushed on through it. `masses`: sum the
    // contact masses (two-way), else k is infinitely heavy.
    MW_INLINE VirtualBoundary collide(std::uint32_t i, Vec3 x, Vec3 from, View<const Vec3> position,
                                      View<const Vec3> velocity, bool masses) const {
        VirtualBoundary k;
        if (fluid_near_solid && !fluid_near_solid[i]) return k;
        Vec3 normal_sum{0, 0, 0};
        Real lattice_weight = 0;
        grid.for_each_solid_around_particle(i, [&](std::uint32_t j) {
            if (type[j] != kSurfaceBoundary) return;
            const std::uint32_t slot = std::uint32_t(solid_slot[j]);
            const Vec3 sbp = position[j];
            // An IBP slot with the SBP type is a melting lattice's exposed vertex.
            const bool lattice = slot < ibp_count;
            const std::uint32_t s = lattice ? slot : slot - ibp_count;
            if (lattice ? !lattice_normal : (!sbp_normal || !(norm2(x - sbp) < sbp_reach * sbp_reach))) return;
            const Vec3 xs = lattice ? lattice_face(sbp, s) : faces().at(sbp, s);
            const Real w = contact_weight(x, xs, reach);
            if (!(w > Real(0))) return;
            Vec3 normal;
            Real inverse_mass = 0;
            if (lattice) {
                const Vec3 stored = lattice_normal[s];
                normal = sbp_normal_toward(stored, norm2(stored) > Real(0) ? kSbpOneSided : kSbpAround, from - sbp);
                if (masses) inverse_mass = lattice_inverse_mass[s];
                lattice_weight += w;
            } else {
                normal = sbp_sides ? sbp_normal_toward(sbp_normal[s], sbp_sides[s], from - sbp) : sbp_normal[s];
                if (masses) inverse_mass = sbp_inverse_mass[s];
            }
            k.weight += w;
            k.position += w * xs;
            k.velocity += w * velocity[j];
            normal_sum += w * normal;
            k.inverse_mass += w * inverse_mass;
        });
        const Real length = norm(normal_sum);
        if (!(k.weight > Real(0)) || !(length > Real(0))) return VirtualBoundary{};
        // Between two lattice faces that look at each other (a one-layer melt in a gap), the
        // mean face would lie between them, beside the particle: no collision (the pressure keeps
        // it there).
        if (lattice_weight > Real(0) && length < Real(kOpposedFaces) * k.weight) return VirtualBoundary{};
        const Real inv_w = Real(1) / k.weight;
        k.position = inv_w * k.position;
        k.velocity = inv_w * k.velocity;
        k.normal = (Real(1) / length) * normal_sum;
        k.inverse_mass *= inv_w;
        return k;
    }

    // Whether fluid particle x moving at v collides with k: within the band of its surface and
    // moving into it. `depth` receives how far x lies in front of that surface.
    MW_INLINE bool collides(const VirtualBoundary& k, Vec3 x, Vec3 v, Real& depth) const {
        if (!k.found()) return false;
        depth = k.depth(x, Real(kSurfacePatchRadius) * reach);
        return depth < band && k.approached_by(v);
    }

    // The position rule alone, for a PCISPH prediction x* of a particle that started the step at
    // `from` with velocity v (against the SBPs where they are at the start of the step, where the
    // density sees them): x* moves along n_k until it is c in front of k's surface.
    MW_INLINE Vec3 correct_predicted(std::uint32_t i, Vec3 x, Vec3 from, Vec3 v, View<const Vec3> position,
                                     View<const Vec3> velocity) const {
        const VirtualBoundary k = collide(i, x, from, position, velocity, false);
        Real depth = 0;
        return collides(k, x, v, depth) ? x + (band - depth) * k.normal : x;
    }
};

// Once a step, after the grid's build: which fluid particles have a moving solid's particle in
// the cells around them (SolidSurface::fluid_near_solid). The same cells as every gather of the
// step (the cells of the start of the step), so skipping the others changes no result.
inline void mark_fluid_near_solids(const DeviceContext& device, std::size_t fluid_count, const GridView grid, View<std::uint8_t> near) {
    parallel_for(device, "solid_contact_near", fluid_count, [=] MW_HD(std::size_t i) {
        near[i] = grid.has_solid_around_particle(static_cast<std::uint32_t>(i)) ? 1 : 0;
    });
}

MW_BACKEND_END
