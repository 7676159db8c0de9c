// What a melting lattice shows the fluid's velocity–position correction (solid_contact.hpp,
// virtual_boundary.hpp; docs/melting.md, "The correction against its faces"). A melting object
// has no mesh surface: its SBPs are the lattice vertices that miss a one-ring neighbour
// (melting.hpp), so the correction meets each at its cell's face, r0/2 in front of it along its
// normal (SolidSurface::lattice_face), or on the vertex where it has no outside, with
//   - a normal from the lattice as it stands: away from the vertices left in its one-ring,
//     n = -Σ (x_j - x_i) / |Σ (x_j - x_i)| over the one-ring neighbours j still in the object,
//     from the store's positions at the start of the step (where the density sees them), so
//     that no rest frame or rotation is needed. Where the vertices left lie about evenly on
//     opposite sides (|Σ| under half what a flat face gives, 3^(D-1) r0: a one-layer sheet, its
//     rim, a line, a lone vertex) the vertex has no outside: it is met from all round, the normal
//     pointing at the fluid particle, as a rod's end is (solid_face.hpp, kSbpAround);
//   - two-way, a contact mass from the regions it is in as they stand after the last rebuild,
//     1/m_d = Σ_r (1/M_r) / n_d² (solid_contact.hpp's rule for an IBP, which it is); a pinned
//     vertex is infinitely heavy.
// Both are per IBP slot, for every vertex of a melting object (zero for the inner ones and those
// gone): the normals every step in stage "neighbors", after the sort; the contact masses when the
// regions or the exposed vertices change (the first step, a step where something melted, a
// checkpoint's load), since nothing else moves them.
#pragma once
#include <cstdint>

#include "algorithms/lsm_regions.hpp"
#include "algorithms/melting_regions.hpp"
#include "algorithms/particle_types.hpp"
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

// How far in front of a melting lattice's exposed vertex, along its normal, its cell's face lies:
// half the spacing (the lattice's cells are r0 wide). The correction and interface tension meet the
// vertex there.
MW_INLINE Real lattice_face_offset(Real spacing) { return Real(0.5) * spacing; }

// The correction's arrays for the melting lattices, by IBP slot (SolidBodies owns them).
struct LatticeFaceArrays {
    Vec3* normal = nullptr;        // null: the correction does not meet the lattices
    Real* inverse_mass = nullptr;  // null: one-way, the lattices infinitely heavy
    Vec3* impulse = nullptr;       // what each took in the last correction (two-way)
};

// What the faces are read from.
struct LatticeFaceInputs {
    const std::int32_t* cell_slot = nullptr;   // the melting grids' cells (melting_regions.hpp)
    const std::int32_t* slot_coord = nullptr;  // per IBP slot: its grid i, j, k
    const std::uint32_t* store_of_slot = nullptr;
    const std::uint8_t* type = nullptr;        // store field
    const Vec3* position = nullptr;            // store field
    const std::uint8_t* pinned = nullptr;      // per IBP slot
    const std::uint32_t* regions_begin = nullptr;  // per IBP slot, into member_index (region ids)
    const std::uint32_t* regions_end = nullptr;
    const std::uint32_t* member_index = nullptr;
    const Real* region_mass = nullptr;
    Real sheet_below = 0;  // m: |Σ (x_j - x_i)| under this, the vertex is met from all round
};

// Half of what a flat face's vertex sums, in r0: the 3^(D-1) vertices of the layer behind it
// each lie r0 behind its plane.
constexpr double lattice_sheet_threshold(int full_ring) { return full_ring == 8 ? 1.5 : 4.5; }

// One melting object's exposed vertices: their normals (see the top of the file).
inline void melting_lattice_normals(const DeviceContext& device, const MeltingGrid g, const LatticeFaceInputs in,
                                    const LatticeFaceArrays out) {
    parallel_for(device, "melting_face_normals", g.count, [=] MW_HD(std::size_t k) {
        const std::uint32_t s = g.base + static_cast<std::uint32_t>(k);
        const std::uint32_t i = in.store_of_slot[s];
        Vec3 normal{0, 0, 0};
        if (i != kMeltedSlot && in.type[i] == kSurfaceBoundary) {
            const std::int32_t* c = in.slot_coord + 3 * std::size_t(s);
            const Vec3 xi = in.position[i];
            Vec3 inward{0, 0, 0};
            g.for_each_one_ring_cell(c[0], c[1], c[2], [&](std::int64_t cell) {
                const std::int32_t t = in.cell_slot[cell];
                if (t < 0) return;
                const std::uint32_t j = in.store_of_slot[t];
                if (j != kMeltedSlot) inward += in.position[j] - xi;
            });
            const Real length = norm(inward);
            if (length > in.sheet_below) normal = (Real(-1) / length) * inward;
        }
        out.normal[s] = normal;
    });
}

// One melting object's exposed vertices: their contact masses, two-way (out.inverse_mass not null).
inline void melting_lattice_contact_masses(const DeviceContext& device, const MeltingGrid g, const LatticeFaceInputs in,
                                           const LatticeFaceArrays out) {
    parallel_for(device, "melting_face_masses", g.count, [=] MW_HD(std::size_t k) {
        const std::uint32_t s = g.base + static_cast<std::uint32_t>(k);
        const std::uint32_t i = in.store_of_slot[s];
        Real inverse_mass = 0;
        if (i != kMeltedSlot && in.type[i] == kSurfaceBoundary && !in.pinned[s]) {
            const std::uint32_t begin = in.regions_begin[s], end = in.regions_end[s];
            Real sum = 0;
            for (std::uint32_t e = begin; e < end; ++e) sum += Real(1) / in.region_mass[in.member_index[e]];
            const Real regions = Real(end - begin);
            inverse_mass = end > begin ? sum / (regions * regions) : Real(0);
        }
        out.inverse_mass[s] = inverse_mass;
    });
}

MW_BACKEND_END
