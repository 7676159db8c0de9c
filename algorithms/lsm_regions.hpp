// Lattice shape matching, start-up part (host only, once): turns the solids of a SimulationSetup
// into flat arrays indexed by a stable "solid slot", ready for upload (see solid_bodies.hpp).
//
// Slots: every IBP of every moving solid, then every SBP, then every GP. The particle store
// re-sorts particles every step; a slot never changes, so all LSM data below is indexed by slot
// and a per-step map slot -> store index finds the particle.
//
// Regions (docs/method.md, "Lattice shape matching"): an elastic object has one region per IBP,
// centred on it, holding the IBPs within w lattice links, i.e. those reachable from the centre in
// at most w steps through existing lattice neighbours (26-neighbourhood). Where the whole
// (2w+1)³ cube exists this is the cube; elsewhere a breadth-first search keeps regions from
// jumping across thin gaps (two fingers one lattice cell apart). Membership is symmetric, so the
// regions containing IBP i are the members of i's own region, and elastic region r has slot r.
// A rigid object has one region over all its IBPs (region ids after the IBP slots).
//
// A melting object (melting.hpp) loses lattice vertices as it melts: its regions are rebuilt over
// the vertices left (rebuild_elastic_object_regions). Removing a vertex can only shrink a region,
// so each region keeps the place it was built with and region_end marks how much of it is in use.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

#include "simulation/simulation.hpp"
#include "algorithms/solid_face.hpp"
#include "algorithms/vec3.hpp"
#include "common/errors.hpp"

namespace mw {

// Symmetric 3×3 matrix.
struct SymMat3 {
    Real xx, yy, zz, xy, xz, yz;
};
MW_INLINE Mat3 sym_to_mat3(const SymMat3& s) { return Mat3{{{s.xx, s.xy, s.xz}, {s.xy, s.yy, s.yz}, {s.xz, s.yz, s.zz}}}; }
MW_INLINE Vec3 operator*(const SymMat3& s, Vec3 v) {
    return Vec3{s.xx * v.x + s.xy * v.y + s.xz * v.z, s.xy * v.x + s.yy * v.y + s.yz * v.z,
                s.xz * v.x + s.yz * v.y + s.zz * v.z};
}

// Per-object constants the kernels need (one small array, indexed by the object's position in
// SimulationSetup::solids).
struct LsmObjectParams {
    Real alpha = 1;         // stiffness α
    Real damping_rate = 0;  // 1/s, per region (lsm.damping)
    Real body_damping_rate = 0;  // 1/s, over the whole body (lsm.body_damping)
    Real friction = 0;      // wall friction
    Real margin = 0;        // r0/2, how far inside its surface its outer IBPs lie (contacts between objects)
    // IBPs stay this far from the domain walls and the static boxes: the margin, and where the
    // object keeps the walls' film (object_keeps_wall_film) kWallFilmLayers fluid spacings more,
    // so that its surface stops a fluid layer short of them (docs/contact.md, "The film").
    Real wall_margin = 0;
    std::uint8_t rigid = 0; // 1 for a rigid object (one region), 0 for an elastic one
    // 1 for a cloth or a rod: each node answers the fluid's pressure on its own inside PCISPH
    // (coupling.strong; coupling.hpp, relax_node_accelerations), and PCISPH meets each of its
    // particles at its own velocity.
    std::uint8_t nodal = 0;
    // 1 for a rigid object and a solid elastic one (not melting): it answers the fluid's pressure
    // inside PCISPH as one body, by a linear and an angular acceleration (coupling.strong;
    // coupling.hpp, relax_object_accelerations).
    std::uint8_t body_answer = 0;
    MW_HD bool answers() const { return body_answer || nodal; }  // inside PCISPH, under coupling.strong
};

struct SbpLink {
    // GP indices (0 .. gp_count) of the triangle's corners; a rod's SBP lies on the segment of
    // corners 0 and 1, and repeats corner 1 as corner 2 (is_segment); a 2D object's SBP lies on
    // the outline's edge from corner 0 to corner 1, and repeats corner 0 as corner 2
    // (is_outline_edge).
    std::uint32_t corner[3];
    Vec3 bary;
    Real sign;  // +1 or -1: orients the deformed triangle's normal like the sampled one
    Real inset;  // m: the SBP sits this far inside the triangle, along its normal
    MW_HD bool is_segment() const { return corner[1] == corner[2]; }
    MW_HD bool is_outline_edge() const { return corner[2] == corner[0] && corner[0] != corner[1]; }
    // The face's direction at corner positions c, before `sign`: a triangle's normal, a rod
    // segment's tangent, an outline edge's in-plane normal (the edge turned clockwise about z,
    // outward for an outline that runs counter-clockwise around the solid).
    MW_HD Vec3 face_direction(const Vec3 c[3]) const {
        const Vec3 edge = c[1] - c[0];
        if (is_segment()) return edge;
        if (is_outline_edge()) return Vec3{edge.y, -edge.x, Real(0)};
        return cross(edge, c[2] - c[0]);
    }
};

struct LsmHostLayout {
    std::size_t ibp_count = 0, sbp_count = 0, gp_count = 0;
    std::vector<std::uint32_t> scene_index;  // per slot: IBPs, then SBPs, then GPs
    // IBPs
    std::vector<Vec3> ibp_rest;
    std::vector<Real> ibp_mass, ibp_split_mass;
    std::vector<std::int32_t> ibp_object;
    std::vector<std::uint8_t> ibp_pinned;
    std::vector<std::uint32_t> ibp_regions_begin, ibp_regions_end;  // into member_index (region ids)
    // Regions: members of region r are member_index[region_offsets[r] .. region_offsets[r+1]);
    // member_index continues with the region ids of rigid objects' IBPs.
    std::vector<std::uint32_t> region_offsets;
    std::vector<std::uint32_t> region_end;  // one past region r's last member (region_offsets[r + 1] as built)
    std::vector<std::uint32_t> member_index;
    std::vector<Real> region_mass;
    std::vector<Vec3> region_c0;
    std::vector<SymMat3> region_A0, region_inertia_inv;
    std::vector<std::int32_t> region_object;
    // Regions too large for one thread to sum (a rigid object's single region) are summed in
    // chunks first, then the chunks' sums per region. Region r owns chunks region_chunks[r] ..
    // region_chunks[r+1] (none when it is summed in one piece); chunk c of region chunk_region[c]
    // starts at member_index[chunk_begin[c]] and ends where the region's next chunk starts, or
    // where the region ends. All empty when no region is chunked.
    std::vector<std::uint32_t> region_chunks, chunk_begin, chunk_region;
    // GPs: normalised weights of Eq. 19, links are IBP slots
    std::vector<Vec3> gp_rest;
    std::vector<std::uint32_t> gp_offsets, gp_links;
    std::vector<Real> gp_weights;
    // SBPs
    std::vector<SbpLink> sbp;
    std::vector<Vec3> sbp_normal;
    // Per SBP, how the fluid meets it (SbpSides, solid_face.hpp): from both sides (cloth) or all
    // round (rods) the correction turns its normal toward the fluid particle. Empty when every SBP
    // is one-sided.
    std::vector<std::uint8_t> sbp_sides;
    std::vector<LsmObjectParams> objects;

    std::size_t region_count() const { return region_mass.size(); }
    std::size_t slot_count() const { return ibp_count + sbp_count + gp_count; }
};

// An object's lattice vertices on a dense grid over their bounding box: at(i, j, k) is the
// vertex's index in the list, or -1 where there is none (or outside the box).
struct LatticeIndex {
    explicit LatticeIndex(const std::vector<std::array<int, 3>>& lattice) {
        if (lattice.empty()) return;
        int hi[3] = {lattice[0][0], lattice[0][1], lattice[0][2]};
        for (int a = 0; a < 3; ++a) lo[a] = lattice[0][a];
        for (const auto& c : lattice)
            for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
        for (int a = 0; a < 3; ++a) dims[a] = hi[a] - lo[a] + 1;
        if (double(dims[0]) * double(dims[1]) * double(dims[2]) > 4e8)
            throw InputError("an object's lattice is too large for LSM region building");
        vertex.assign(std::size_t(dims[0] * dims[1] * dims[2]), -1);
        for (std::size_t p = 0; p < lattice.size(); ++p) {
            std::int32_t& v = vertex[cell(lattice[p][0] - lo[0], lattice[p][1] - lo[1], lattice[p][2] - lo[2])];
            if (v >= 0) throw InputError("two IBPs of one object share a lattice point");
            v = std::int32_t(p);
        }
    }
    // Cell index of grid coordinates (relative to lo), inside the box.
    std::size_t cell(long i, long j, long k) const { return std::size_t((k * dims[1] + j) * dims[0] + i); }
    std::int32_t at(long i, long j, long k) const {
        if (i < 0 || j < 0 || k < 0 || i >= dims[0] || j >= dims[1] || k >= dims[2]) return -1;
        return vertex[cell(i, j, k)];
    }
    int lo[3] = {0, 0, 0};
    long dims[3] = {0, 0, 0};
    std::vector<std::int32_t> vertex;
};

namespace lsm_detail {

// Members (local IBP indices, increasing) of the region centred on each IBP of one object; with
// `only`, of those whose entry is set (the others are left empty).
inline void build_elastic_regions(const std::vector<std::array<int, 3>>& lattice, int w,
                                  std::vector<std::vector<std::uint32_t>>& members,
                                  const std::vector<std::uint8_t>* only = nullptr) {
    const std::size_t n = lattice.size();
    members.assign(n, {});
    if (n == 0) return;
    const LatticeIndex grid(lattice);
    const int* lo = grid.lo;
    auto cell = [&](long i, long j, long k) { return grid.cell(i, j, k); };
    auto at = [&](long i, long j, long k) { return grid.at(i, j, k); };
    std::vector<int> depth(grid.vertex.size(), -1);  // BFS marks, reset after each search
    std::vector<std::size_t> touched;
    for (std::size_t p = 0; p < n; ++p) {
        if (only && !(*only)[p]) continue;
        const long ci = lattice[p][0] - lo[0], cj = lattice[p][1] - lo[1], ck = lattice[p][2] - lo[2];
        std::vector<std::uint32_t>& m = members[p];
        bool full = true;
        for (long k = ck - w; k <= ck + w && full; ++k)
            for (long j = cj - w; j <= cj + w && full; ++j)
                for (long i = ci - w; i <= ci + w && full; ++i) full = at(i, j, k) >= 0;
        if (full) {
            for (long k = ck - w; k <= ck + w; ++k)
                for (long j = cj - w; j <= cj + w; ++j)
                    for (long i = ci - w; i <= ci + w; ++i) m.push_back(std::uint32_t(at(i, j, k)));
        } else {
            std::vector<std::uint32_t> frontier{std::uint32_t(p)};
            depth[cell(ci, cj, ck)] = 0;
            touched.push_back(cell(ci, cj, ck));
            m.push_back(std::uint32_t(p));
            for (int d = 1; d <= w; ++d) {
                std::vector<std::uint32_t> next;
                for (std::uint32_t q : frontier) {
                    const long qi = lattice[q][0] - lo[0], qj = lattice[q][1] - lo[1], qk = lattice[q][2] - lo[2];
                    for (long dk = -1; dk <= 1; ++dk)
                        for (long dj = -1; dj <= 1; ++dj)
                            for (long di = -1; di <= 1; ++di) {
                                const std::int32_t r = at(qi + di, qj + dj, qk + dk);
                                if (r < 0) continue;
                                const std::size_t c = cell(qi + di, qj + dj, qk + dk);
                                if (depth[c] >= 0) continue;
                                depth[c] = d;
                                touched.push_back(c);
                                next.push_back(std::uint32_t(r));
                                m.push_back(std::uint32_t(r));
                            }
                }
                frontier.swap(next);
            }
            for (std::size_t c : touched) depth[c] = -1;
            touched.clear();
        }
        std::sort(m.begin(), m.end());
    }
}

// Members (local IBP indices, increasing) of the region centred on each IBP of one object whose
// IBPs have no lattice: those within w links of it on the graph (CSR `offsets`, `links`; cloth:
// the mesh's edges). Graph distance is symmetric, so membership is too, as on the lattice.
inline void build_graph_regions(const std::vector<std::uint32_t>& offsets, const std::vector<std::uint32_t>& links,
                                int w, std::vector<std::vector<std::uint32_t>>& members) {
    const std::size_t n = offsets.empty() ? 0 : offsets.size() - 1;
    members.assign(n, {});
    std::vector<int> depth(n, -1);
    for (std::size_t p = 0; p < n; ++p) {
        std::vector<std::uint32_t>& m = members[p];
        std::vector<std::uint32_t> frontier{std::uint32_t(p)};
        depth[p] = 0;
        m.push_back(std::uint32_t(p));
        for (int d = 1; d <= w; ++d) {
            std::vector<std::uint32_t> next;
            for (std::uint32_t q : frontier)
                for (std::uint32_t e = offsets[q]; e < offsets[q + 1]; ++e) {
                    const std::uint32_t r = links[e];
                    if (depth[r] >= 0) continue;
                    depth[r] = d;
                    next.push_back(r);
                    m.push_back(r);
                }
            frontier.swap(next);
        }
        for (std::uint32_t q : m) depth[q] = -1;
        std::sort(m.begin(), m.end());
    }
}

// Regularised inverse of a symmetric positive semi-definite matrix (in double): line-like
// regions have no inertia about their axis, and no angular momentum about it either. Also in
// kernels (a rigid object at the walls, lsm.hpp).
MW_INLINE SymMat3 regularised_inverse(double xx, double yy, double zz, double xy, double xz, double yz) {
    const double reg = 1e-4 * (xx + yy + zz) + 1e-300;
    xx += reg, yy += reg, zz += reg;
    const double c00 = yy * zz - yz * yz, c01 = xz * yz - xy * zz, c02 = xy * yz - xz * yy;
    const double c11 = xx * zz - xz * xz, c12 = xy * xz - xx * yz, c22 = xx * yy - xy * xy;
    const double det = xx * c00 + xy * c01 + xz * c02;
    const double s = det != 0 ? 1.0 / det : 0.0;
    return SymMat3{Real(c00 * s), Real(c11 * s), Real(c22 * s), Real(c01 * s), Real(c02 * s), Real(c12 * s)};
}

}  // namespace lsm_detail

// A region with more members than this is summed in chunks (see LsmHostLayout). Elastic regions
// stay below it for w <= 3 ((2w+1)^3 = 343 members), so their sums keep one thread and one order.
constexpr std::size_t kRegionSerialMembers = 512;

namespace lsm_detail {
// Chunks of about sqrt(n) members (at least 256): the chunk pass and the pass over a region's
// chunk sums then both loop about sqrt(n) times (198 chunks of 256 for bench_lsm's 50.7k-IBP cube).
inline void append_region_chunks(LsmHostLayout& L, std::uint32_t region, std::size_t serial_limit) {
    const std::uint32_t begin = L.region_offsets[region], end = L.region_offsets[region + 1];
    const std::size_t n = end - begin;
    if (n > serial_limit) {
        const std::size_t root = static_cast<std::size_t>(std::ceil(std::sqrt(double(n))));
        const std::uint32_t size = static_cast<std::uint32_t>(std::max<std::size_t>(256, root));
        for (std::uint32_t b = begin; b < end; b += std::min(size, end - b)) {
            L.chunk_begin.push_back(b);
            L.chunk_region.push_back(region);
        }
    }
    L.region_chunks[region + 1] = static_cast<std::uint32_t>(L.chunk_begin.size());
}
}  // namespace lsm_detail

// A slot whose particle has melted (melting.hpp): store_of_slot holds this, and every per-slot
// kernel skips it.
constexpr std::uint32_t kMeltedSlot = 0xffffffffu;

// The region arrays as a rebuild after melting writes them (melting_regions.hpp), by slot: an
// elastic region is centred on its IBP, so region and slot share an index.
struct MeltingRegionArrays {
    const Vec3* rest = nullptr;                  // per IBP slot
    const Real* mass = nullptr;                  // per IBP slot: the IBP's whole mass
    const std::uint32_t* region_offsets = nullptr;  // each region's place (its capacity: to the next)
    const std::uint32_t* regions_begin = nullptr;   // per IBP slot: the first of its regions in member_index
    std::uint32_t* region_end = nullptr;
    std::uint32_t* regions_end = nullptr;
    std::uint32_t* member_index = nullptr;
    Real* split_mass = nullptr;
    Real* region_mass = nullptr;
    Vec3* region_c0 = nullptr;
    SymMat3* region_A0 = nullptr;
    SymMat3* region_inertia_inv = nullptr;
};

// A region's rest sums: its mass, centre c0, A0 = Σ m̃ q qᵀ and inverse rest inertia, from its
// members' rest positions and split masses (both indexed by slot), in double. One function for the
// host's build and the device's rebuild after melting (melting_regions.hpp), so that both give the
// same bits.
struct RegionRestSums {
    Real mass = 0;
    Vec3 c0{0, 0, 0};
    SymMat3 A0{}, inertia_inv{};
};
MW_INLINE RegionRestSums region_rest_sums(const std::uint32_t* members_begin, const std::uint32_t* members_end,
                                          const Real* split_mass, const Vec3* rest) {
    double M = 0, c[3] = {0, 0, 0};
    for (const std::uint32_t* it = members_begin; it != members_end; ++it) {
        const double w = split_mass[*it];
        const Vec3 x = rest[*it];
        M += w, c[0] += w * x.x, c[1] += w * x.y, c[2] += w * x.z;
    }
    if (M > 0) c[0] /= M, c[1] /= M, c[2] /= M;
    double a[6] = {0, 0, 0, 0, 0, 0};  // xx yy zz xy xz yz
    for (const std::uint32_t* it = members_begin; it != members_end; ++it) {
        const double w = split_mass[*it];
        const Vec3 x = rest[*it];
        const double q[3] = {x.x - c[0], x.y - c[1], x.z - c[2]};
        a[0] += w * q[0] * q[0], a[1] += w * q[1] * q[1], a[2] += w * q[2] * q[2];
        a[3] += w * q[0] * q[1], a[4] += w * q[0] * q[2], a[5] += w * q[1] * q[2];
    }
    RegionRestSums out;
    out.mass = Real(M);
    // Nudge c0 (in Real) so that Σ m̃ (x0 - c0), evaluated in Real as the kernels do, is as
    // close to zero as rounding allows: the goals' momentum balance rests on that sum, and
    // its rounding error, divided by Δt, would otherwise show up as a slow drift of momentum.
    Vec3 c0{Real(c[0]), Real(c[1]), Real(c[2])};
    for (int pass = 0; pass < 3 && M > 0; ++pass) {
        double e[3] = {0, 0, 0};
        for (const std::uint32_t* it = members_begin; it != members_end; ++it) {
            const Vec3 q = rest[*it] - c0;
            const double w = split_mass[*it];
            e[0] += w * double(q.x), e[1] += w * double(q.y), e[2] += w * double(q.z);
        }
        c0 = c0 + Vec3{Real(e[0] / M), Real(e[1] / M), Real(e[2] / M)};
    }
    out.c0 = c0;
    out.A0 = SymMat3{Real(a[0]), Real(a[1]), Real(a[2]), Real(a[3]), Real(a[4]), Real(a[5])};
    const double tr = a[0] + a[1] + a[2];
    out.inertia_inv = lsm_detail::regularised_inverse(tr - a[0], tr - a[1], tr - a[2], -a[3], -a[4], -a[5]);
    return out;
}

namespace lsm_detail {
// Region r's rest sums (region_rest_sums) into the host layout.
inline void set_region_rest_sums(LsmHostLayout& L, std::size_t r, const std::uint32_t* members_begin,
                                 const std::uint32_t* members_end) {
    const RegionRestSums sums = region_rest_sums(members_begin, members_end, L.ibp_split_mass.data(), L.ibp_rest.data());
    L.region_mass[r] = sums.mass;
    L.region_c0[r] = sums.c0;
    L.region_A0[r] = sums.A0;
    L.region_inertia_inv[r] = sums.inertia_inv;
}
// A particle index of a solid's lists must name a particle of the setup.
inline void check_particle_index(std::uint32_t i, std::size_t particles, const std::string& what,
                                 const std::string& name) {
    if (i >= particles) throw InputError("solid '" + name + "': " + what + " index out of range");
}

// Every moving solid's GPs, linked to its IBPs by Eq. 19's normalised weights, and its SBPs on
// their triangles of GPs (the sign makes the deformed triangle's normal point as the rest normal).
inline void add_mesh_links(LsmHostLayout& L, const SimulationSetup& setup, const std::vector<std::size_t>& ibp_base,
                           const std::vector<std::size_t>& sbp_base, const std::vector<std::size_t>& gp_base) {
    const std::size_t n_particles = setup.position.size();
    auto check_index = [&](std::uint32_t i, const std::string& what, const std::string& name) {
        check_particle_index(i, n_particles, what, name);
    };
    L.gp_offsets.assign(1, 0);
    L.gp_rest.reserve(L.gp_count);
    L.sbp.reserve(L.sbp_count);
    for (std::size_t o = 0; o < setup.solids.size(); ++o) {
        const SolidSetup& s = setup.solids[o];
        if (s.kind == SolidKind::kStatic) continue;
        if (s.gp_offsets.size() != s.gp.size() + 1 || s.gp_links.size() != s.gp_weights.size())
            throw InputError("solid '" + s.name + "': malformed GP links");
        for (std::size_t g = 0; g < s.gp.size(); ++g) {
            check_index(s.gp[g], "gp", s.name);
            L.scene_index[L.ibp_count + L.sbp_count + gp_base[o] + g] = s.gp[g];
            L.gp_rest.push_back(setup.position[s.gp[g]]);
            double total = 0;
            for (int k = s.gp_offsets[g]; k < s.gp_offsets[g + 1]; ++k) total += s.gp_weights[std::size_t(k)];
            const int count = s.gp_offsets[g + 1] - s.gp_offsets[g];
            if (count <= 0) throw InputError("solid '" + s.name + "': a GP has no IBP link");
            for (int k = s.gp_offsets[g]; k < s.gp_offsets[g + 1]; ++k) {
                const int d = s.gp_links[std::size_t(k)];
                if (d < 0 || std::size_t(d) >= s.ibp.size()) throw InputError("solid '" + s.name + "': GP link out of range");
                L.gp_links.push_back(std::uint32_t(ibp_base[o] + std::size_t(d)));
                L.gp_weights.push_back(total > 0 ? Real(s.gp_weights[std::size_t(k)] / total) : Real(1.0 / count));
            }
            L.gp_offsets.push_back(std::uint32_t(L.gp_links.size()));
        }
        if (s.sbp_corners.size() != s.sbp.size() || s.sbp_barycentric.size() != s.sbp.size() ||
            s.sbp_normal.size() != s.sbp.size() || (!s.sbp_inset.empty() && s.sbp_inset.size() != s.sbp.size()))
            throw InputError("solid '" + s.name + "': SBP lists differ in length");
        const std::size_t first_sbp = L.sbp.size();
        for (std::size_t k = 0; k < s.sbp.size(); ++k) {
            check_index(s.sbp[k], "sbp", s.name);
            L.scene_index[L.ibp_count + sbp_base[o] + k] = s.sbp[k];
            SbpLink link;
            Vec3 corner[3];
            for (int c = 0; c < 3; ++c) {
                const int g = s.sbp_corners[k][c];
                if (g < 0 || std::size_t(g) >= s.gp.size()) throw InputError("solid '" + s.name + "': SBP corner out of range");
                link.corner[c] = std::uint32_t(gp_base[o] + std::size_t(g));
                corner[c] = setup.position[s.gp[std::size_t(g)]];
            }
            link.bary = s.sbp_barycentric[k];
            link.sign = dot(link.face_direction(corner), s.sbp_normal[k]) < 0 ? Real(-1) : Real(1);
            link.inset = s.sbp_inset.empty() ? Real(0) : s.sbp_inset[k];
            if (!(link.inset >= Real(0)) || !(link.inset < s.spacing))
                throw InputError("solid '" + s.name + "': an SBP's inset is outside [0, r0)");
            L.sbp.push_back(link);
            L.sbp_normal.push_back(s.sbp_normal[k]);
        }
        // Flags for every SBP so far once any is not one-sided; none stored before that.
        const std::uint8_t sides = s.kind == SolidKind::kCloth ? kSbpTwoSided : s.kind == SolidKind::kRod ? kSbpAround : kSbpOneSided;
        if (sides != kSbpOneSided) L.sbp_sides.resize(first_sbp, kSbpOneSided);
        if (sides != kSbpOneSided || !L.sbp_sides.empty()) L.sbp_sides.resize(L.sbp.size(), sides);
    }
}

}  // namespace lsm_detail

// The walls' film (coupling.wall_film), in fluid spacings between an object's surface and a wall
// or static box it rests on: the fluid rests half a spacing from a wall's face and about one
// spacing from an object's face lined with its surface particles (docs/contact.md, "The film").
constexpr Real kWallFilmLayers = Real(1.5);

// How close an object's IBPs start to the domain walls and the static boxes (the nearest one's
// distance; infinite with neither). In 2D they have no faces normal to z.
inline Real start_clearance(const SimulationSetup& setup, const SolidSetup& s) {
    const BoundaryParams& b = setup.params.boundary;
    const bool planar = setup.params.dimensions == 2;
    const Vec3 lo = setup.params.domain_min, hi = setup.params.domain_max;
    Real closest = std::numeric_limits<Real>::infinity();
    for (std::uint32_t index : s.ibp) {
        const Vec3 x = setup.position[index];
        if (b.walls) {
            closest = std::min({closest, x.x - lo.x, hi.x - x.x, x.y - lo.y, hi.y - x.y});
            if (!planar) closest = std::min({closest, x.z - lo.z, hi.z - x.z});
        }
        for (const StaticBoxFaces& box : b.static_boxes) {
            const Real dx = std::max({box.lo.x - x.x, Real(0), x.x - box.hi.x});
            const Real dy = std::max({box.lo.y - x.y, Real(0), x.y - box.hi.y});
            const Real dz = planar ? Real(0) : std::max({box.lo.z - x.z, Real(0), x.z - box.hi.z});
            closest = std::min(closest, std::sqrt(dx * dx + dy * dy + dz * dz));
        }
    }
    return closest;
}

// Whether an object keeps the walls' film (coupling.wall_film): in a scene with fluid, unless it
// is pinned (anchored, it never lands) or starts closer to a wall or a static box than the film
// would hold it (a box set on the floor stays where the scene puts it, touching). The static mesh
// objects are met without it: their distance grids reach about 1.45 r0 past their surface
// (scene_builder.cpp, add_static_object_distance), short of the film's 2 r0.
inline bool object_keeps_wall_film(const SimulationSetup& setup, const SolidSetup& s, Real margin) {
    if (!setup.keeps_wall_film()) return false;
    if (std::any_of(s.pinned.begin(), s.pinned.end(), [](std::uint8_t p) { return p != 0; })) return false;
    return start_clearance(setup, s) >= margin + kWallFilmLayers * setup.params.fluid.spacing;
}

// Builds the slot arrays and regions of every moving solid (elastic or rigid) of `setup`.
// `serial_limit`: regions with more members are summed in chunks (a parameter for tests).
inline LsmHostLayout build_lsm_layout(const SimulationSetup& setup, std::size_t serial_limit = kRegionSerialMembers) {
    LsmHostLayout L;
    const std::size_t n_particles = setup.position.size();
    auto check_index = [&](std::uint32_t i, const std::string& what, const std::string& name) {
        lsm_detail::check_particle_index(i, n_particles, what, name);
    };
    std::vector<std::size_t> ibp_base(setup.solids.size()), sbp_base(setup.solids.size()), gp_base(setup.solids.size());
    for (std::size_t o = 0; o < setup.solids.size(); ++o) {
        const SolidSetup& s = setup.solids[o];
        if (s.kind == SolidKind::kStatic) continue;
        ibp_base[o] = L.ibp_count;
        L.ibp_count += s.ibp.size();
    }
    for (std::size_t o = 0; o < setup.solids.size(); ++o) {
        const SolidSetup& s = setup.solids[o];
        if (s.kind == SolidKind::kStatic) continue;
        sbp_base[o] = L.sbp_count;
        L.sbp_count += s.sbp.size();
        gp_base[o] = L.gp_count;
        L.gp_count += s.gp.size();
    }
    L.objects.resize(setup.solids.size());
    L.region_offsets.assign(L.ibp_count + 1, 0);
    L.region_mass.assign(L.ibp_count, 0);
    L.region_c0.assign(L.ibp_count, Vec3{0, 0, 0});
    L.region_A0.assign(L.ibp_count, SymMat3{0, 0, 0, 0, 0, 0});
    L.region_inertia_inv.assign(L.ibp_count, SymMat3{0, 0, 0, 0, 0, 0});
    L.region_object.assign(L.ibp_count, 0);
    L.ibp_rest.resize(L.ibp_count);
    L.ibp_mass.resize(L.ibp_count);
    L.ibp_split_mass.resize(L.ibp_count);
    L.ibp_object.resize(L.ibp_count);
    L.ibp_pinned.assign(L.ibp_count, 0);
    L.ibp_regions_begin.resize(L.ibp_count);
    L.ibp_regions_end.resize(L.ibp_count);
    L.scene_index.resize(L.slot_count());

    // Members of every region (elastic: per IBP; rigid: appended after the IBP slots).
    std::vector<std::vector<std::uint32_t>> region_members(L.ibp_count);  // slots
    std::vector<std::size_t> rigid_objects;
    for (std::size_t o = 0; o < setup.solids.size(); ++o) {
        const SolidSetup& s = setup.solids[o];
        if (s.kind == SolidKind::kStatic) continue;
        if (s.ibp.empty()) throw InputError("solid '" + s.name + "' has no inner particles (IBPs); make it larger or decrease the spacing");
        const bool graph = is_thin(s.kind);
        if (!graph && s.lattice.size() != s.ibp.size())
            throw InputError("solid '" + s.name + "': lattice and ibp lists differ in length");
        if (graph && (s.ibp_graph_offsets.size() != s.ibp.size() + 1 || s.ibp_graph_offsets.back() != s.ibp_graph_links.size()))
            throw InputError("solid '" + s.name + "': malformed IBP graph");
        if (!s.ibp_mass.empty() && s.ibp_mass.size() != s.ibp.size())
            throw InputError("solid '" + s.name + "': IBP mass list has the wrong length");
        if (!s.pinned.empty() && s.pinned.size() != s.ibp.size()) throw InputError("solid '" + s.name + "': pinned list has the wrong length");
        if (!(s.stiffness > 0 && s.stiffness <= 1)) throw InputError("solid '" + s.name + "': stiffness α must be in (0, 1]");
        if (!(s.density > 0) || !(s.spacing > 0)) throw InputError("solid '" + s.name + "': density and spacing must be > 0");
        if (s.region_half_width < 1) throw InputError("solid '" + s.name + "': region half-width w must be >= 1");
        LsmObjectParams& P = L.objects[o];
        P.alpha = s.kind == SolidKind::kRigid ? Real(1) : s.stiffness;
        P.damping_rate = s.damping;
        P.body_damping_rate = s.kind == SolidKind::kRigid ? Real(0) : s.body_damping;
        P.friction = s.wall_friction;
        P.margin = Real(0.5) * s.spacing;
        const bool film = object_keeps_wall_film(setup, s, P.margin);
        P.wall_margin = P.margin + (film ? kWallFilmLayers * setup.params.fluid.spacing : Real(0));
        P.rigid = s.kind == SolidKind::kRigid ? 1 : 0;
        P.nodal = is_thin(s.kind) ? 1 : 0;
        P.body_answer = s.kind == SolidKind::kRigid || (s.kind == SolidKind::kElastic && !s.melts()) ? 1 : 0;
        const Real mass = s.density * s.spacing * s.spacing * s.spacing;
        const std::size_t base = ibp_base[o];
        for (std::size_t k = 0; k < s.ibp.size(); ++k) {
            check_index(s.ibp[k], "ibp", s.name);
            L.scene_index[base + k] = s.ibp[k];
            L.ibp_rest[base + k] = setup.position[s.ibp[k]];
            L.ibp_mass[base + k] = s.ibp_mass.empty() ? mass : s.ibp_mass[k];
            if (!(L.ibp_mass[base + k] > Real(0))) throw InputError("solid '" + s.name + "': an IBP's mass is not positive");
            L.ibp_object[base + k] = std::int32_t(o);
            L.ibp_pinned[base + k] = s.pinned.empty() ? 0 : s.pinned[k];
        }
        if (s.kind != SolidKind::kRigid) {
            std::vector<std::vector<std::uint32_t>> local;
            if (graph) {
                for (std::uint32_t link : s.ibp_graph_links)
                    if (link >= s.ibp.size()) throw InputError("solid '" + s.name + "': IBP graph link out of range");
                lsm_detail::build_graph_regions(s.ibp_graph_offsets, s.ibp_graph_links, s.region_half_width, local);
            } else {
                lsm_detail::build_elastic_regions(s.lattice, s.region_half_width, local);
            }
            for (std::size_t k = 0; k < local.size(); ++k) {
                for (std::uint32_t& m : local[k]) m += std::uint32_t(base);
                region_members[base + k] = std::move(local[k]);
                L.region_object[base + k] = std::int32_t(o);
            }
        } else {
            rigid_objects.push_back(o);
            std::vector<std::uint32_t> all(s.ibp.size());
            for (std::size_t k = 0; k < all.size(); ++k) all[k] = std::uint32_t(base + k);
            region_members.push_back(std::move(all));
            L.region_object.push_back(std::int32_t(o));
        }
    }
    const std::size_t n_regions = region_members.size();
    L.region_offsets.assign(n_regions + 1, 0);
    L.region_mass.resize(n_regions);
    L.region_c0.resize(n_regions);
    L.region_A0.resize(n_regions);
    L.region_inertia_inv.resize(n_regions);
    std::vector<std::uint32_t> regions_of_count(L.ibp_count, 0);
    for (std::size_t r = 0; r < n_regions; ++r) {
        L.region_offsets[r + 1] = L.region_offsets[r] + std::uint32_t(region_members[r].size());
        for (std::uint32_t m : region_members[r]) ++regions_of_count[m];
    }
    if (double(L.region_offsets[n_regions]) + double(L.ibp_count) > 4.0e9)
        throw InputError("too many LSM region members (more than 2^32); use a smaller region half-width w");
    L.region_end.assign(L.region_offsets.begin() + 1, L.region_offsets.end());
    L.member_index.reserve(L.region_offsets[n_regions] + L.ibp_count);
    for (auto& m : region_members) L.member_index.insert(L.member_index.end(), m.begin(), m.end());
    L.region_chunks.assign(n_regions + 1, 0);
    for (std::size_t r = 0; r < n_regions; ++r) lsm_detail::append_region_chunks(L, std::uint32_t(r), serial_limit);
    if (L.chunk_begin.empty()) L.region_chunks.clear();  // nothing chunked: nothing stored or read per step
    for (std::size_t s = 0; s < L.ibp_count; ++s) L.ibp_split_mass[s] = L.ibp_mass[s] / Real(regions_of_count[s]);
    // Regions containing each IBP: its own region's members (elastic), or its object's region.
    for (std::size_t s = 0; s < L.ibp_count; ++s) {
        if (!region_members[s].empty()) {
            L.ibp_regions_begin[s] = L.region_offsets[s];
            L.ibp_regions_end[s] = L.region_offsets[s + 1];
        }
    }
    for (std::size_t k = 0; k < rigid_objects.size(); ++k) {
        const std::size_t o = rigid_objects[k];
        const std::uint32_t region = std::uint32_t(L.ibp_count + k);
        for (std::size_t j = 0; j < setup.solids[o].ibp.size(); ++j) {
            const std::size_t s = ibp_base[o] + j;
            L.ibp_regions_begin[s] = std::uint32_t(L.member_index.size());
            L.member_index.push_back(region);
            L.ibp_regions_end[s] = std::uint32_t(L.member_index.size());
        }
    }
    // Rest sums per region, in double.
    for (std::size_t r = 0; r < n_regions; ++r)
        lsm_detail::set_region_rest_sums(L, r, region_members[r].data(), region_members[r].data() + region_members[r].size());
    lsm_detail::add_mesh_links(L, setup, ibp_base, sbp_base, gp_base);
    return L;
}

// Per lattice vertex, how many of its 26 one-ring neighbours are present (among the `alive` ones
// when given: per vertex, 0 for a gone one); in 2D (a lattice in one plane) 8 at most. A melting
// object's vertex with all of them (full_one_ring) is an IBP, any other an SBP (docs/method.md,
// "Particles").
inline std::vector<std::uint8_t> lattice_one_ring_counts(const std::vector<std::array<int, 3>>& lattice,
                                                         const std::vector<std::uint8_t>& alive = {}) {
    std::vector<std::uint8_t> count(lattice.size(), 0);
    if (lattice.empty()) return count;
    const LatticeIndex grid(lattice);
    for (std::size_t p = 0; p < lattice.size(); ++p) {
        if (!alive.empty() && !alive[p]) continue;
        const long ci = lattice[p][0] - grid.lo[0], cj = lattice[p][1] - grid.lo[1], ck = lattice[p][2] - grid.lo[2];
        int n = 0;
        for (long dk = -1; dk <= 1; ++dk)
            for (long dj = -1; dj <= 1; ++dj)
                for (long di = -1; di <= 1; ++di) {
                    const std::int32_t q = grid.at(ci + di, cj + dj, ck + dk);
                    n += (di | dj | dk) != 0 && q >= 0 && (alive.empty() || alive[std::size_t(q)]);
                }
        count[p] = std::uint8_t(n);
    }
    return count;
}
// A lattice vertex's one-ring neighbours in `dimensions` (2 or 3): 3^D - 1.
constexpr int full_one_ring(int dimensions) { return dimensions == 2 ? 8 : 26; }

// Rebuilds the regions of one elastic object, its IBPs in slots [base, base + lattice.size()),
// over the vertices still `alive` (per slot, over all of L's IBP slots): the regions, split masses
// and rest sums it would have been built with had it held only those. Each region stays where it
// was built, shorter (L.region_end); a gone vertex's region is empty and it is in none.
// `gone` (local indices), when given, lists the vertices lost since the last rebuild: only the
// regions they can have touched are redone. A region loses members only through a gone vertex
// within w links of its centre (any path it lost ran through one), so memberships and split
// masses change within w lattice steps of a gone vertex, and rest sums, which read the members'
// split masses, within 2w. Without `gone`, every region is redone (a checkpoint's load).
inline void rebuild_elastic_object_regions(LsmHostLayout& L, const std::vector<std::array<int, 3>>& lattice, int w,
                                           std::size_t base, const std::vector<std::uint8_t>& alive,
                                           const std::vector<std::uint32_t>* gone = nullptr) {
    const std::size_t n = lattice.size();
    // Per local vertex: its lattice-step distance to the nearest gone vertex, capped at 2w + 1.
    const int far = 2 * w + 1;
    std::vector<int> reach(n, gone ? far : 0);
    if (gone) {
        const LatticeIndex grid(lattice);
        for (std::uint32_t g : *gone) {
            const long ci = lattice[g][0] - grid.lo[0], cj = lattice[g][1] - grid.lo[1], ck = lattice[g][2] - grid.lo[2];
            for (long dk = -2 * w; dk <= 2 * w; ++dk)
                for (long dj = -2 * w; dj <= 2 * w; ++dj)
                    for (long di = -2 * w; di <= 2 * w; ++di) {
                        const std::int32_t q = grid.at(ci + di, cj + dj, ck + dk);
                        if (q < 0) continue;
                        const int d = int(std::max({std::labs(di), std::labs(dj), std::labs(dk)}));
                        reach[std::size_t(q)] = std::min(reach[std::size_t(q)], d);
                    }
        }
    }
    std::vector<std::array<int, 3>> live;
    std::vector<std::uint32_t> live_slot;
    std::vector<std::uint8_t> redo;  // per live vertex: its membership is redone
    for (std::size_t k = 0; k < n; ++k) {
        const std::size_t s = base + k;
        if (!alive[s]) {
            L.region_end[s] = L.region_offsets[s];
            L.ibp_regions_end[s] = L.ibp_regions_begin[s];
            L.region_mass[s] = 0;
            continue;
        }
        live.push_back(lattice[k]);
        live_slot.push_back(std::uint32_t(s));
        redo.push_back(reach[k] <= w ? 1 : 0);
    }
    std::vector<std::vector<std::uint32_t>> local;
    lsm_detail::build_elastic_regions(live, w, local, &redo);
    for (std::size_t q = 0; q < live.size(); ++q) {
        if (!redo[q]) continue;
        const std::uint32_t s = live_slot[q];
        const std::uint32_t begin = L.region_offsets[s];
        if (local[q].size() > L.region_offsets[s + 1] - begin)
            throw std::logic_error("LSM region rebuild: a region grew when its object lost particles");
        for (std::size_t m = 0; m < local[q].size(); ++m) L.member_index[begin + m] = live_slot[local[q][m]];
        L.region_end[s] = begin + std::uint32_t(local[q].size());
        L.ibp_regions_end[s] = L.region_end[s];  // membership is symmetric: its regions are its members
        L.ibp_split_mass[s] = L.ibp_mass[s] / Real(local[q].size());
    }
    for (std::uint32_t s : live_slot)
        if (reach[s - base] <= 2 * w)
            lsm_detail::set_region_rest_sums(L, s, L.member_index.data() + L.region_offsets[s],
                                             L.member_index.data() + L.region_end[s]);
}

}  // namespace mw
