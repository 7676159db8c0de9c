// A melting object's lattice on the device, and what a step's phase change does to it there
// (melting.hpp): the vertices that melt become fluid, those they leave exposed become SBPs, and the
// LSM regions are rebuilt over the vertices left. What is left is the slot map's (a melted slot
// holds kMeltedSlot) and what is exposed the store's types (an IBP is a vertex with its full
// one-ring), so nothing else is kept. The host learns only how many melted and how many were
// exposed.
//
// The rebuild gives, bit for bit, what rebuild_elastic_object_regions (lsm_regions.hpp) gives on
// the host: a region is redone where a vertex gone this step lies within w lattice steps of its
// centre (its members and split mass), its rest sums where one lies within 2w (they read the
// members' split masses). A region's members are the vertices left that a walk of at most w
// one-ring steps over vertices left reaches from its centre; they lie in the box of half-width w
// round it, so each region's search is a flood fill over that box (at most (2 · 8 + 1)³ cells for
// the schema's largest w), then its members sorted by slot, as the host sorts them.
#pragma once
#include <array>
#include <cstdint>
#include <vector>

#include "algorithms/lsm_regions.hpp"
#include "algorithms/particle_types.hpp"
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

// The largest region half-width the device rebuild handles: the schema's (objects[].lsm.w).
constexpr int kMeltingLargestHalfWidth = 8;
constexpr int kMeltingBoxSide = 2 * kMeltingLargestHalfWidth + 1;
constexpr int kMeltingBoxWords = (kMeltingBoxSide * kMeltingBoxSide * kMeltingBoxSide + 63) / 64;

// One melting object's lattice: its IBP slots [base, base + count) and the dense grid over its
// bounding box, whose cells [first_cell, first_cell + dims[0] dims[1] dims[2]) of the concatenated
// cell arrays hold the slot of the vertex there (-1: none).
struct MeltingGrid {
    std::uint32_t base = 0, count = 0;
    std::uint32_t first_cell = 0;
    std::int32_t dims[3] = {0, 0, 0};
    std::int32_t half_width = 2;  // w
    std::int32_t full_ring = 26;  // one-ring neighbours of an inner vertex: 26, or 8 in a plane
    MW_HD std::uint32_t cell_count() const { return std::uint32_t(dims[0]) * std::uint32_t(dims[1]) * std::uint32_t(dims[2]); }
    // The cell at grid coordinates (i, j, k), or -1 outside the box.
    MW_HD std::int64_t cell(std::int32_t i, std::int32_t j, std::int32_t k) const {
        if (i < 0 || j < 0 || k < 0 || i >= dims[0] || j >= dims[1] || k >= dims[2]) return -1;
        return std::int64_t(first_cell) + (std::int64_t(k) * dims[1] + j) * dims[0] + i;
    }
    // Calls visit(n) for each cell n of (i, j, k)'s one-ring inside the box (not the cell itself),
    // z slowest and x fastest: the order every sum over a vertex's one-ring takes.
    template <class Visit>
    MW_INLINE void for_each_one_ring_cell(std::int32_t i, std::int32_t j, std::int32_t k, Visit&& visit) const {
        for (std::int32_t dk = -1; dk <= 1; ++dk)
            for (std::int32_t dj = -1; dj <= 1; ++dj)
                for (std::int32_t di = -1; di <= 1; ++di) {
                    if ((di | dj | dk) == 0) continue;
                    const std::int64_t n = cell(i + di, j + dj, k + dk);
                    if (n >= 0) visit(n);
                }
    }
};

// The store's side of a phase change: the slot map and the particles' fields it changes.
struct PhaseChangeData {
    std::uint32_t* store_of_slot = nullptr;
    std::uint8_t* type = nullptr;  // store fields
    std::int32_t* solid_slot = nullptr;
    std::int32_t* object = nullptr;
    Real* density = nullptr;
    Real rest_density = 0;
    // The impulses the correction gave the exposed vertices in this step (melting_faces.hpp), per
    // IBP slot, which the next step's coupling would apply: a vertex that melts takes its own
    // into its velocity as fluid. Null: none (one-way, or the correction off).
    Vec3* lattice_impulse = nullptr;
    Vec3* velocity = nullptr;  // store field
    Real inverse_fluid_mass = 0;
};
// The per-step state of the melting lattices and the region arrays the rebuild writes.
struct MeltingLatticeData {
    const std::int32_t* cell_slot = nullptr;  // per cell: the slot of its vertex, -1 none
    const std::int32_t* slot_coord = nullptr; // per IBP slot of a melting object: its grid i, j, k (3 each)
    const std::uint8_t* melts = nullptr;      // per IBP slot: it melts this step
    std::uint8_t* exposed = nullptr;          // per IBP slot: became an SBP this step
    std::uint8_t* reach = nullptr;            // per cell: lattice steps to the nearest vertex gone this step (at most 2w + 1)
    std::uint8_t* reach_next = nullptr;       // per cell: the dilation's other buffer
    MeltingRegionArrays regions;
    PhaseChangeData particles;
    // Whether slot s's vertex is still in its object.
    MW_HD bool left(std::int32_t s) const { return particles.store_of_slot[s] != kMeltedSlot; }
};

// This step's reach, by 2w dilations of the vertices that melt (Chebyshev distance, as the host
// measures it); the result lands back in `reach`, 2w being even.
inline void melting_reach(const DeviceContext& device, const MeltingGrid g, const MeltingLatticeData d) {
    const std::uint8_t far = std::uint8_t(2 * g.half_width + 1);
    parallel_for(device, "melting_reach_seed", g.cell_count(), [=] MW_HD(std::size_t c) {
        const std::int32_t s = d.cell_slot[g.first_cell + c];
        d.reach[g.first_cell + c] = s >= 0 && d.melts[s] ? std::uint8_t(0) : far;
    });
    std::uint8_t* from = d.reach;
    std::uint8_t* to = d.reach_next;
    for (int round = 0; round < 2 * g.half_width; ++round) {
        parallel_for(device, "melting_reach_dilate", g.cell_count(), [=] MW_HD(std::size_t c) {
            const std::int32_t i = std::int32_t(c % std::uint32_t(g.dims[0]));
            const std::int32_t j = std::int32_t((c / std::uint32_t(g.dims[0])) % std::uint32_t(g.dims[1]));
            const std::int32_t k = std::int32_t(c / (std::uint32_t(g.dims[0]) * std::uint32_t(g.dims[1])));
            std::uint8_t best = from[g.first_cell + c];
            g.for_each_one_ring_cell(i, j, k, [&](std::int64_t n) {
                if (from[n] + 1 < best) best = std::uint8_t(from[n] + 1);
            });
            to[g.first_cell + c] = best;
        });
        std::uint8_t* t = from;
        from = to;
        to = t;
    }
}

// The vertices that melt become fluid and leave the slot map; then an IBP (a vertex with its full
// one-ring) that lost a one-ring neighbour is exposed and becomes an SBP.
inline void melting_phase_change(const DeviceContext& device, const MeltingGrid g, const MeltingLatticeData d) {
    parallel_for(device, "melting_to_fluid", g.count, [=] MW_HD(std::size_t k) {
        const std::uint32_t s = g.base + std::uint32_t(k);
        if (!d.melts[s]) return;
        const PhaseChangeData p = d.particles;
        const std::uint32_t i = p.store_of_slot[s];
        p.type[i] = kFluid;
        p.solid_slot[i] = -1;
        p.object[i] = -1;
        p.density[i] = p.rest_density;
        p.store_of_slot[s] = kMeltedSlot;
        if (p.lattice_impulse) {
            p.velocity[i] += p.inverse_fluid_mass * p.lattice_impulse[s];
            p.lattice_impulse[s] = Vec3{0, 0, 0};
        }
    });
    parallel_for(device, "melting_exposed", g.count, [=] MW_HD(std::size_t k) {
        const std::uint32_t s = g.base + std::uint32_t(k);
        d.exposed[s] = 0;
        const std::int32_t* at = d.slot_coord + 3 * std::size_t(s);
        if (!d.left(std::int32_t(s)) || d.reach[g.cell(at[0], at[1], at[2])] > 1) return;
        const std::uint32_t i = d.particles.store_of_slot[s];
        if (d.particles.type[i] != kInnerBoundary) return;
        int left = 0;
        g.for_each_one_ring_cell(at[0], at[1], at[2], [&](std::int64_t n) {
            const std::int32_t q = d.cell_slot[n];
            left += q >= 0 && d.left(q);
        });
        if (left == g.full_ring) return;
        d.particles.type[i] = kSurfaceBoundary;
        d.exposed[s] = 1;
    });
}

// Regions within w of a gone vertex: their members, ends and split masses; a gone vertex's region
// is emptied.
inline void melting_region_members(const DeviceContext& device, const MeltingGrid g, const MeltingLatticeData d) {
    parallel_for(device, "melting_region_members", g.count, [=] MW_HD(std::size_t k) {
        const std::uint32_t s = g.base + std::uint32_t(k);
        const MeltingRegionArrays r = d.regions;
        if (d.melts[s]) {
            r.region_end[s] = r.region_offsets[s];
            r.regions_end[s] = r.regions_begin[s];
            r.region_mass[s] = 0;
            return;
        }
        const std::int32_t* at = d.slot_coord + 3 * std::size_t(s);
        if (!d.left(std::int32_t(s)) || d.reach[g.cell(at[0], at[1], at[2])] > g.half_width) return;
        // Flood fill over the box of half-width w round the centre, w one-ring steps.
        const std::int32_t w = g.half_width, side = 2 * w + 1;
        std::uint64_t reached[kMeltingBoxWords], frontier[kMeltingBoxWords], next[kMeltingBoxWords];
        const int words = (side * side * side + 63) / 64;
        for (int b = 0; b < words; ++b) reached[b] = frontier[b] = 0;
        const int centre = (w * side + w) * side + w;
        reached[centre >> 6] |= std::uint64_t(1) << (centre & 63);
        frontier[centre >> 6] |= std::uint64_t(1) << (centre & 63);
        for (std::int32_t step = 1; step <= w; ++step) {
            for (int b = 0; b < words; ++b) next[b] = 0;
            for (std::int32_t bk = 0; bk < side; ++bk)
                for (std::int32_t bj = 0; bj < side; ++bj)
                    for (std::int32_t bi = 0; bi < side; ++bi) {
                        const int box = (bk * side + bj) * side + bi;
                        if (reached[box >> 6] >> (box & 63) & 1) continue;
                        const std::int64_t cell = g.cell(at[0] + bi - w, at[1] + bj - w, at[2] + bk - w);
                        if (cell < 0) continue;
                        const std::int32_t q = d.cell_slot[cell];
                        if (q < 0 || !d.left(q)) continue;
                        bool linked = false;
                        for (std::int32_t dk = -1; dk <= 1 && !linked; ++dk)
                            for (std::int32_t dj = -1; dj <= 1 && !linked; ++dj)
                                for (std::int32_t di = -1; di <= 1 && !linked; ++di) {
                                    const std::int32_t ni = bi + di, nj = bj + dj, nk = bk + dk;
                                    if (ni < 0 || nj < 0 || nk < 0 || ni >= side || nj >= side || nk >= side) continue;
                                    const int n = (nk * side + nj) * side + ni;
                                    linked = frontier[n >> 6] >> (n & 63) & 1;
                                }
                        if (linked) next[box >> 6] |= std::uint64_t(1) << (box & 63);
                    }
            for (int b = 0; b < words; ++b) {
                reached[b] |= next[b];
                frontier[b] = next[b];
            }
        }
        // The members, sorted by slot (insertion into the region's own range).
        const std::uint32_t begin = r.region_offsets[s], capacity = r.region_offsets[s + 1] - begin;
        std::uint32_t n = 0;
        for (int box = 0; box < side * side * side; ++box) {
            if (!(reached[box >> 6] >> (box & 63) & 1)) continue;
            const std::int32_t bi = box % side, bj = (box / side) % side, bk = box / (side * side);
            const std::uint32_t q = std::uint32_t(d.cell_slot[g.cell(at[0] + bi - w, at[1] + bj - w, at[2] + bk - w)]);
            if (n == capacity) break;  // cannot happen: a region only shrinks as its object melts
            std::uint32_t m = n++;
            while (m > 0 && r.member_index[begin + m - 1] > q) {
                r.member_index[begin + m] = r.member_index[begin + m - 1];
                --m;
            }
            r.member_index[begin + m] = q;
        }
        r.region_end[s] = begin + n;
        r.regions_end[s] = begin + n;  // membership is symmetric: its regions are its members
        r.split_mass[s] = r.mass[s] / Real(n);
    });
}

// Rest sums of the regions within 2w of a gone vertex (after every split mass is current).
inline void melting_region_rest_sums(const DeviceContext& device, const MeltingGrid g, const MeltingLatticeData d) {
    parallel_for(device, "melting_region_rest_sums", g.count, [=] MW_HD(std::size_t k) {
        const std::uint32_t s = g.base + std::uint32_t(k);
        const std::int32_t* at = d.slot_coord + 3 * std::size_t(s);
        if (!d.left(std::int32_t(s)) || d.reach[g.cell(at[0], at[1], at[2])] > 2 * g.half_width) return;
        const MeltingRegionArrays r = d.regions;
        const RegionRestSums sums = region_rest_sums(r.member_index + r.region_offsets[s], r.member_index + r.region_end[s],
                                                     r.split_mass, r.rest);
        r.region_mass[s] = sums.mass;
        r.region_c0[s] = sums.c0;
        r.region_A0[s] = sums.A0;
        r.region_inertia_inv[s] = sums.inertia_inv;
    });
}

// One step's update of a lattice whose `melts` flags are set: reach, the phase change and the
// exposure, the regions' members and rest sums.
inline void update_melting_lattice(const DeviceContext& device, const MeltingGrid g, const MeltingLatticeData d) {
    melting_reach(device, g, d);
    melting_phase_change(device, g, d);
    melting_region_members(device, g, d);
    melting_region_rest_sums(device, g, d);
}

// The grid of a melting object's `lattice` (its IBP slots from `base`): its cells appended to
// `cell_slot` and its vertices' grid coordinates written into `slot_coord` (3 per IBP slot).
inline MeltingGrid melting_grid(const std::vector<std::array<int, 3>>& lattice, std::size_t base, int half_width,
                                int full_ring, std::vector<std::int32_t>& cell_slot, std::vector<std::int32_t>& slot_coord) {
    const LatticeIndex grid(lattice);
    MeltingGrid g;
    g.base = std::uint32_t(base);
    g.count = std::uint32_t(lattice.size());
    g.first_cell = std::uint32_t(cell_slot.size());
    for (int a = 0; a < 3; ++a) g.dims[a] = std::int32_t(grid.dims[a]);
    g.half_width = half_width;
    g.full_ring = full_ring;
    for (const std::int32_t v : grid.vertex) cell_slot.push_back(v < 0 ? -1 : std::int32_t(base) + v);
    for (std::size_t k = 0; k < lattice.size(); ++k)
        for (int a = 0; a < 3; ++a) slot_coord[3 * (base + k) + std::size_t(a)] = lattice[k][a] - grid.lo[a];
    return g;
}

MW_BACKEND_END
