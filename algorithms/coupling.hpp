// Two-way coupling, the fluid's side of it (docs/method.md, "Two-way coupling"): every force a moving solid's
// boundary particle exerted on the fluid in this step goes back to the solid, reversed, and
// reaches its IBPs, which LSM moves.
//
// 1. The reaction on each SBP and IBP of a moving solid, gathered over its fluid neighbours with
//    exactly the terms the fluid summed (no float atomics, so it is deterministic):
//      pressure (Akinci 2012; pcisph.hpp)  F_b = Σ_i m ψ_b (p_i/ρ_i²) ∇W(x*_i - x_b)
//      friction (Eq. 8, when on)           F_b = -Σ_i m (μ_w/ρ0) V_b ∇²W(x_i - x_b) (v_b - v_i)
//      interface tension (Eq. 9, SBPs)     F_s = Σ_i η_s m ρ0 V_s W(x_is) x_is / |x_is|
//                                          (interface_tension.hpp; positions of the step's start)
//    with the last PCISPH iteration's predicted positions x* (the fluid's, and the solids' where
//    PCISPH predicts them) and pressures, so that the pair's
//    two forces cancel to rounding: the fluid and the solids together conserve momentum. With the
//    velocity–position correction against solids on, an SBP's reaction also carries the impulse
//    the correction gave it at the end of the last step (solid_contact.hpp), as J / Δt.
// 2. Each IBP's force: its own reaction, plus a share of each SBP's. The shares are the transpose
//    of the interpolation that moves the SBPs (an SBP follows its triangle's GPs by barycentric
//    weights, a GP its linked IBPs by Eq. 19's normalised weights): an SBP's shares sum to 1, so
//    no force is lost or made, and the work the force does on the SBP is the work its shares do
//    on the IBPs, up to Eq. 19's rotation term. docs/method.md's Eq. 10 as printed,
//    F_d = Σ_s W(x_ds) F_s / Σ_s W(x_ds), averages instead of sharing: an IBP next to n SBPs
//    takes about one SBP's force, not n shares of theirs, so the total on a body is not the sum
//    of its SBPs' forces (docs/coupling.md).
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include "algorithms/lsm.hpp"
#include "algorithms/lsm_regions.hpp"
#include "algorithms/neighbor_grid.hpp"
#include "algorithms/particle_types.hpp"
#include "algorithms/pcisph.hpp"
#include "algorithms/solid_face.hpp"

namespace mw {

// Host, once: the SBP -> IBP shares in compressed rows by IBP slot (offsets[ibp_count + 1]),
// each row ordered by SBP, so that the per-IBP sum has one fixed order.
struct SurfaceShares {
    std::vector<std::uint32_t> offsets, sbp;  // sbp: SBP index 0 .. sbp_count
    std::vector<Real> weight;
};
inline SurfaceShares surface_shares(const LsmHostLayout& L) {
    // Each SBP's share of each IBP: Σ over its corners of bary_c × (the corner GP's Eq. 19 weight).
    std::vector<std::vector<std::pair<std::uint32_t, double>>> rows(L.ibp_count);
    std::vector<std::pair<std::uint32_t, double>> share;  // (IBP slot, weight) of one SBP
    for (std::size_t k = 0; k < L.sbp_count; ++k) {
        const SbpLink& link = L.sbp[k];
        const double bary[3] = {link.bary.x, link.bary.y, link.bary.z};
        share.clear();
        for (int c = 0; c < 3; ++c) {
            const std::uint32_t g = link.corner[c];
            for (std::uint32_t e = L.gp_offsets[g]; e < L.gp_offsets[g + 1]; ++e)
                share.emplace_back(L.gp_links[e], bary[c] * double(L.gp_weights[e]));
        }
        std::sort(share.begin(), share.end());
        double total = 0;
        for (const auto& s : share) total += s.second;
        // Normalised in double, so that the shares of one SBP sum to 1 whatever the barycentric
        // weights' rounding; an IBP reached through two corners gets one merged share.
        for (std::size_t e = 0; e < share.size();) {
            const std::uint32_t d = share[e].first;
            double w = 0;
            for (; e < share.size() && share[e].first == d; ++e) w += share[e].second;
            if (total != 0 && w != 0) rows[d].emplace_back(std::uint32_t(k), w / total);
        }
    }
    SurfaceShares out;
    out.offsets.assign(1, 0);
    for (const auto& row : rows) {
        for (const auto& e : row) {
            out.sbp.push_back(e.first);
            out.weight.push_back(Real(e.second));
        }
        out.offsets.push_back(std::uint32_t(out.sbp.size()));
    }
    return out;
}

}  // namespace mw

MW_BACKEND_BEGIN

// What the two kernels read and write, by solid slot (solid_bodies.hpp: IBPs, then SBPs, then GPs).
struct CouplingData {
    const std::uint32_t* store_of_slot = nullptr;
    std::uint32_t ibp_count = 0, sbp_count = 0;
    Vec3* reaction = nullptr;  // per IBP and SBP slot, this step's
    Vec3* force = nullptr;     // per IBP: what LSM applies
    const std::uint32_t* share_offsets = nullptr;
    const std::uint32_t* share_sbp = nullptr;
    const Real* share_weight = nullptr;
    // The impulses the velocity–position correction gave the SBPs in the last step (per SBP;
    // null without it, solid_contact.hpp): they join this step's reaction as J / Δt.
    const Vec3* sbp_contact_impulse = nullptr;
    // The same per IBP slot, for a melting lattice's exposed vertices; null without a melting object.
    const Vec3* lattice_contact_impulse = nullptr;
    Real inverse_dt = 0;
    // Interface tension's η per SBP (interface_tension.hpp); null: none. It pulls toward the
    // SBPs' face points.
    const Real* sbp_eta = nullptr;
    SbpFaces faces;
    // The same per IBP slot for a melting object's lattice, and the store's types: only its
    // exposed vertices (kSurfaceBoundary) pull, toward their faces, `lattice_inset` in front of
    // them along their normals (melting_faces.hpp); null: none.
    const Real* lattice_eta = nullptr;
    const std::uint8_t* type = nullptr;
    const Vec3* lattice_normal = nullptr;
    Real lattice_inset = 0;
    // Inside PCISPH (coupling.strong): only the slots of the objects that answer there (rigid
    // and solid elastic ones, cloths: LsmObjectParams::answers) are gathered (each slot's object, and the
    // objects' parameters); null: every slot.
    const std::int32_t* slot_object = nullptr;
    const LsmObjectParams* answering_only = nullptr;
};

// The pairs the fluid summed: in grid mode all in the 27 cells (the relation is symmetric:
// b is in the cells around i exactly when i is in those around b); with neighbour lists only
// those within `list_radius` of each other at the start of the step, tested as the lists'
// build tests them (neighbor_list.hpp). list_radius 0: grid mode.
// With lists, each slot's pairs are listed once per step (list_slot_pairs), so that the reaction
// gathered in every PCISPH iteration (coupling.strong) and after it walks a short row instead of
// 27 cells: `rows` of `row_capacity` per slot, `row_count` each (kRowOverflow: the slot had more,
// and gathers from the grid).
struct FluidPairs {
    GridView grid;
    std::size_t fluid_end = 0, solid_end = 0;  // the moving solids' boundary particles: [fluid_end, solid_end)
    Real list_radius2 = 0;
    // Where PCISPH met the solids' particles (pcisph.hpp): the reaction meets them there too.
    SolidLookahead lookahead;
    const std::uint32_t* rows = nullptr;
    const std::uint32_t* row_count = nullptr;
    std::uint32_t row_capacity = 0;
};
constexpr std::uint32_t kRowOverflow = 0xffffffffu;

// The rows of FluidPairs (lists only): each slot's fluid neighbours within the list radius at the
// start of the step, in the grid's order, so that a row's sums are the grid's to the bit.
inline void list_slot_pairs(const DeviceContext& device, const FluidPairs pairs, std::size_t slot_count,
                            const std::uint32_t* store_of_slot, View<const Vec3> position, std::uint32_t* rows,
                            std::uint32_t* row_count) {
    parallel_for(device, "coupling_pairs", slot_count, [=] MW_HD(std::size_t s) {
        const std::uint32_t b = store_of_slot[s];
        if (b < pairs.fluid_end || b >= pairs.solid_end) {
            row_count[s] = 0;
            return;
        }
        const Vec3 xb = position[b];
        std::uint32_t* row = rows + s * pairs.row_capacity;
        std::uint32_t n = 0;
        pairs.grid.for_each_fluid(xb, [&](std::uint32_t i) {
            if (norm2(position[i] - xb) < pairs.list_radius2) {
                if (n < pairs.row_capacity) row[n] = i;
                ++n;
            }
        });
        row_count[s] = n <= pairs.row_capacity ? n : kRowOverflow;
    });
}

template <class Kernel>
void fluid_reaction_on_solids(const DeviceContext& device, const FluidPairs pairs, const CouplingData d, View<const Vec3> position,
                              View<const Vec3> velocity, View<const Vec3> predicted, View<const Real> boundary_volume,
                              View<const Real> pressure_term, FluidConstants<Kernel> c, bool friction) {
    const Real pressure_scale = c.mass * c.rest_density;         // m ρ0 (ψ_b = ρ0 V_b)
    const Real friction_scale = -c.mass * c.wall_viscosity / c.rest_density;  // -m μ_w / ρ0
    const bool lists = pairs.list_radius2 > Real(0);
    parallel_for(device, "coupling_reaction", std::size_t(d.ibp_count) + d.sbp_count, [=] MW_HD(std::size_t s) {
        if (d.answering_only && !d.answering_only[d.slot_object[s]].answers()) return;
        const std::uint32_t b = d.store_of_slot[s];
        // A solid particle that left the grid (counted as lost) meets no fluid.
        if (b < pairs.fluid_end || b >= pairs.solid_end) {
            d.reaction[s] = Vec3{0, 0, 0};
            return;
        }
        const std::uint32_t listed = pairs.rows ? pairs.row_count[s] : kRowOverflow;
        Vec3 reaction{0, 0, 0};
        // A slot with no fluid pair (most of a large object's, and all its inner ones) takes only
        // the correction's impulses.
        if (listed != 0) {
            const Vec3 xb = position[b], vb = velocity[b];
            const Real eta = s >= d.ibp_count ? (d.sbp_eta ? d.sbp_eta[s - d.ibp_count] : Real(0))
                                               : (d.lattice_eta && d.type[b] == kSurfaceBoundary ? d.lattice_eta[s] : Real(0));
            Vec3 pressure_sum{0, 0, 0}, friction_sum{0, 0, 0}, tension_sum{0, 0, 0};
            // Where this iteration's sums met b (its placement is kept for them; pcisph.hpp).
            const Vec3 xb_met = pairs.lookahead.met_position(b, position);
            const Vec3 xb_face = !(eta > Real(0)) ? xb
                                 : s >= d.ibp_count ? d.faces.at(xb, static_cast<std::uint32_t>(s - d.ibp_count))
                                                    : xb + d.lattice_inset * d.lattice_normal[s];
            const Real h2 = c.kernel.h * c.kernel.h;
            const auto add = [&](std::uint32_t i, Real paired) {
                const Vec3 xi = position[i];
                const Vec3 r = predicted[i] - xb_met;
                pressure_sum += (paired * pressure_term[i]) * c.kernel.grad_W_r2(r, norm2(r));
                if (friction) friction_sum += c.kernel.laplacian_visc_r2(norm2(xi - xb)) * (vb - velocity[i]);
                if (eta > Real(0) && norm2(xi - xb) < h2) {
                    const Vec3 x_is = xi - xb_face;
                    const Real r2 = norm2(x_is);
                    const Real w = c.kernel.W_r2(r2);
                    if (w > Real(0) && r2 > Real(0)) tension_sum += (w / std::sqrt(r2)) * x_is;
                }
            };
            if (listed != kRowOverflow) {
                const std::uint32_t* row = pairs.rows + s * pairs.row_capacity;
                for (std::uint32_t k = 0; k < listed; ++k) add(row[k], Real(1));
            } else {
                pairs.grid.for_each_fluid(xb, [&](std::uint32_t i) {
                    add(i, lists ? (norm2(position[i] - xb) < pairs.list_radius2 ? Real(1) : Real(0)) : Real(1));
                });
            }
            const Real vb_volume = boundary_volume[b];
            reaction = (pressure_scale * vb_volume) * pressure_sum + (friction_scale * vb_volume) * friction_sum +
                       (pressure_scale * vb_volume * eta) * tension_sum;
        }
        if (d.sbp_contact_impulse && s >= d.ibp_count)
            reaction += d.inverse_dt * d.sbp_contact_impulse[s - d.ibp_count];
        if (d.lattice_contact_impulse && s < d.ibp_count) reaction += d.inverse_dt * d.lattice_contact_impulse[s];
        d.reaction[s] = reaction;
    });
}

// Each IBP's force: its own reaction and its shares of the SBPs' (see the top of the file).
inline void gather_solid_forces(const DeviceContext& device, const CouplingData d) {
    parallel_for(device, "coupling_to_ibps", d.ibp_count, [=] MW_HD(std::size_t s) {
        if (d.answering_only && !d.answering_only[d.slot_object[s]].answers()) return;
        Vec3 f = d.reaction[s];
        for (std::uint32_t e = d.share_offsets[s]; e < d.share_offsets[s + 1]; ++e)
            f += d.share_weight[e] * d.reaction[d.ibp_count + d.share_sbp[e]];
        d.force[s] = f;
    });
}


// Strong coupling (coupling.strong): rigid and solid elastic objects (LsmObjectParams::body_answer)
// answer the fluid's pressure inside the PCISPH iterations, each as one body. Each iteration meets
// such an object where the step takes it under a linear and an angular acceleration
// (SolidLookahead::object_response: a rigid object's particles from their own velocities, an
// elastic one's from its mean velocity); the fluid's reaction at that iteration
// gives the accelerations it implies, G = (g + F/M, I⁻¹ τ) (F and τ the fluid's force and torque
// on the object's IBPs about its centre, the coupling's reaction gathered as above; M, I its mass
// and inertia), and the expected accelerations move toward G. The domain's walls bound G as LSM
// does: no object is expected to pass the box shrunk by its margin (its IBPs' extent moved at
// its velocity), so the fluid is never asked to carry a body that rests on the floor.
// Taken whole, a light object overshoots: the fluid it pushes weighs more than it does, so its
// answer to its own answer grows every iteration (partitioned fluid–structure coupling's
// added-mass instability). Aitken's Δ² relaxation (Küttler & Wall 2008) sets each object's step
// from its last two residuals r = G - a: a += ω r,
// ω_k = -ω_{k-1} r_{k-1}·(r_k - r_{k-1}) / |r_k - r_{k-1}|², within [kMinRelaxation, 1], from
// kFirstRelaxation (the angular part scaled by the object's half-diagonal). Only the answering
// objects' particles are gathered inside PCISPH (CouplingData::answering_only).
// An elastic object's answer sees its motion as a body, not its deformation, which its
// whole-body damping (lsm.body_damping, 5/s by default) keeps down: without it the answer stirred
// the heavy elastic cubes at CFL 1 into gaining energy (docs/coupling.md).
struct ObjectIbps {
    const std::uint32_t* begin = nullptr;  // per object, its first IBP slot (and one past the last)
    const std::uint32_t* store_of_slot = nullptr;
    const Real* mass = nullptr;  // per IBP slot
    const LsmObjectParams* params = nullptr;  // per object (whether it answers as one body, its wall margin)
    std::size_t count = 0;
};
struct ResponseRelaxation {
    Vec3 linear{0, 0, 0}, angular{0, 0, 0};  // the last residual (angular scaled by the object's size)
    Real omega = 0;                          // the last ω; 0: no update yet in this try
};
constexpr Real kFirstRelaxation = Real(0.5);
constexpr Real kMinRelaxation = Real(0.01);

struct ResponseStep {
    Vec3 gravity{0, 0, 0};
    Vec3 domain_min{0, 0, 0}, domain_max{0, 0, 0};
    Real dt = 0;
};

// An expected acceleration `a` bounded by the domain's walls: what spans [lo, hi] and moves at v
// is not expected to shift by dt (v + dt a) past the box shrunk by `margin` on any axis.
MW_INLINE Vec3 bounded_by_walls(Vec3 a, Vec3 v, Vec3 lo, Vec3 hi, Real margin, const ResponseStep& step) {
    const Real lo_room[3] = {step.domain_min.x + margin - lo.x, step.domain_min.y + margin - lo.y,
                             step.domain_min.z + margin - lo.z};
    const Real hi_room[3] = {step.domain_max.x - margin - hi.x, step.domain_max.y - margin - hi.y,
                             step.domain_max.z - margin - hi.z};
    const Real vv[3] = {v.x, v.y, v.z};
    Real* g[3] = {&a.x, &a.y, &a.z};
    const Real inverse_dt2 = Real(1) / (step.dt * step.dt);
    for (int k = 0; k < 3; ++k) {
        const Real shift = step.dt * vv[k] + step.dt * step.dt * *g[k];
        if (shift < lo_room[k]) *g[k] = (lo_room[k] - step.dt * vv[k]) * inverse_dt2;
        if (shift > hi_room[k]) *g[k] = (hi_room[k] - step.dt * vv[k]) * inverse_dt2;
    }
    return a;
}

// A new try: every object expected to keep its velocity.
inline void start_object_responses(const DeviceContext& device, std::size_t object_count, ObjectResponse* response,
                                   ResponseRelaxation* relaxation) {
    parallel_for(device, "strong_coupling_start", object_count, [=] MW_HD(std::size_t o) {
        response[o] = ObjectResponse{};
        relaxation[o] = ResponseRelaxation{};
    });
}

inline void relax_object_accelerations(const DeviceContext& device, ObjectIbps objects, View<const Vec3> position,
                                       View<const Vec3> velocity, const Vec3* ibp_force, ResponseStep step,
                                       const ObjectResponse* response, ObjectResponse* next,
                                       ResponseRelaxation* relaxation) {
    parallel_for(device, "strong_coupling_relax", objects.count, [=] MW_HD(std::size_t o) {
        const ObjectResponse now = response[o];
        const LsmObjectParams params = objects.params[o];
        if (!params.body_answer) {
            next[o] = now;
            return;
        }
        // Sums relative to the first IBP (float keeps the body's size, not its place).
        std::uint32_t first = objects.begin[o];
        while (first < objects.begin[o + 1] && objects.store_of_slot[first] == kMeltedSlot) ++first;
        if (first == objects.begin[o + 1]) {
            next[o] = now;
            return;
        }
        const Vec3 anchor = position[objects.store_of_slot[first]];
        BodySums body;
        Vec3 force{0, 0, 0}, torque{0, 0, 0};  // torque about the anchor
        Vec3 lo{0, 0, 0}, hi{0, 0, 0};          // the IBPs' extent, from the anchor
        for (std::uint32_t s = first; s < objects.begin[o + 1]; ++s) {
            const std::uint32_t i = objects.store_of_slot[s];
            if (i == kMeltedSlot) continue;
            const Vec3 r = position[i] - anchor;
            body.add(objects.mass[s], r, velocity[i]);
            force += ibp_force[s];
            torque += cross(r, ibp_force[s]);
            lo = Vec3{r.x < lo.x ? r.x : lo.x, r.y < lo.y ? r.y : lo.y, r.z < lo.z ? r.z : lo.z};
            hi = Vec3{r.x > hi.x ? r.x : hi.x, r.y > hi.y ? r.y : hi.y, r.z > hi.z ? r.z : hi.z};
        }
        const BodyMotion motion = body_motion(body);
        // G: gravity and the fluid's force, and the fluid's torque about the centre.
        ObjectResponse target;
        target.centre = anchor + motion.centre;
        target.linear = step.gravity + force / body.M;
        target.angular = motion.inverse_inertia * (torque - cross(motion.centre, force));
        // The walls: the object's expected shift dt (V + dt G) keeps its extent inside the box.
        target.linear = bounded_by_walls(target.linear, motion.velocity, anchor + lo, anchor + hi, params.wall_margin, step);
        // Aitken over (linear, size × angular), one ω per object.
        const Real size = Real(0.5) * norm(hi - lo);
        const Vec3 r_linear = target.linear - now.linear, r_angular = size * (target.angular - now.angular);
        ResponseRelaxation& state = relaxation[o];
        Real omega = kFirstRelaxation;
        if (state.omega > Real(0)) {
            const Vec3 d_linear = r_linear - state.linear, d_angular = r_angular - state.angular;
            const Real d2 = norm2(d_linear) + norm2(d_angular);
            omega = d2 > Real(0) ? -state.omega * (dot(state.linear, d_linear) + dot(state.angular, d_angular)) / d2
                                 : state.omega;
            omega = omega < kMinRelaxation ? kMinRelaxation : omega > Real(1) ? Real(1) : omega;
        }
        state.linear = r_linear;
        state.angular = r_angular;
        state.omega = omega;
        next[o].linear = now.linear + omega * (target.linear - now.linear);
        next[o].angular = now.angular + omega * (target.angular - now.angular);
        next[o].centre = target.centre;
    });
}

// Strong coupling of a cloth (LsmObjectParams::nodal): its nodes weigh less than the fluid they
// hold up, and answered after the solve, they overshoot (a 300 kg/m3 cloth under a stream rang up
// to 60 m/s and blew up at CFL steps, and at a fixed 1 ms; it held at 0.5 ms). Inside PCISPH each
// node answers as LSM will move it: the fluid's forces F (each IBP's reaction and its shares of
// the SBPs') act through the regions (lsm.hpp: region r accelerates by Σ F_j / n_j / M_r over
// its members j, each force split among the n_j regions that hold j), and a node by the mean of
// its regions' accelerations (their rotation left out). Its expected acceleration is a = o + that,
// o what the last step gave it apart from the fluid (gravity, the shape matching's pull, damping,
// the walls: its velocity change over the last step less the fluid's part of it; gravity alone in
// the first step), so that a cloth held up by its own stiffness is not expected to fall. Pinned
// nodes expect nothing. A node is not expected past the domain's walls (the box shrunk by its
// margin). The expected accelerations move toward their targets by one Aitken ω per cloth, as the
// rigid objects' do (relax_object_accelerations). An SBP expects its triangle's corners'
// accelerations, by its barycentric weights.
struct NodeResponse {
    const std::uint32_t* object_begin = nullptr;  // per object, its first IBP slot (and one past the last)
    const LsmObjectParams* params = nullptr;      // per object
    const std::int32_t* slot_object = nullptr;    // per IBP and SBP slot
    const std::uint32_t* store_of_slot = nullptr;
    const std::uint8_t* pinned = nullptr;         // per IBP slot
    const Vec3* force = nullptr;                  // per IBP slot: the fluid's, this iteration
    // The regions (lsm_regions.hpp): a cloth's region r is centred on IBP slot r.
    const std::uint32_t* regions_begin = nullptr;  // per IBP slot, into member_index (its regions)
    const std::uint32_t* regions_end = nullptr;
    const std::uint32_t* region_offsets = nullptr;  // per region, into member_index (its members)
    const std::uint32_t* region_end = nullptr;
    const std::uint32_t* member_index = nullptr;
    const Real* region_mass = nullptr;
    Vec3* region_acceleration = nullptr;          // per IBP slot (a cloth's region), scratch
    Vec3* fluid_acceleration = nullptr;           // per IBP slot: the mean of its regions', scratch
    const Vec3* other = nullptr;                  // per IBP slot: o above
    Vec3* target_residual = nullptr;              // per IBP slot: this iteration's r = target - a
    Vec3* last_residual = nullptr;                // per IBP slot: the last iteration's
    ResponseRelaxation* relaxation = nullptr;     // per object: ω
    const SbpLink* sbp = nullptr;                 // per SBP: its triangle of GPs
    const std::uint32_t* gp_offsets = nullptr;    // per GP: its IBP links and weights
    const std::uint32_t* gp_links = nullptr;
    const Real* gp_weights = nullptr;
    std::uint32_t ibp_count = 0, sbp_count = 0;
    std::size_t object_count = 0;
};

// The acceleration `force` gives each cloth node through its regions (n.fluid_acceleration).
inline void node_fluid_accelerations(const DeviceContext& device, const NodeResponse n, const Vec3* force) {
    parallel_for(device, "strong_coupling_nodes_regions", n.ibp_count, [=] MW_HD(std::size_t r) {
        if (!n.params[n.slot_object[r]].nodal) return;
        Vec3 f{0, 0, 0};
        for (std::uint32_t k = n.region_offsets[r]; k < n.region_end[r]; ++k) {
            const std::uint32_t j = n.member_index[k];
            f += force[j] / Real(n.regions_end[j] - n.regions_begin[j]);
        }
        n.region_acceleration[r] = f / n.region_mass[r];
    });
    parallel_for(device, "strong_coupling_nodes_mean", n.ibp_count, [=] MW_HD(std::size_t s) {
        if (!n.params[n.slot_object[s]].nodal) return;
        Vec3 a{0, 0, 0};
        const std::uint32_t begin = n.regions_begin[s], end = n.regions_end[s];
        for (std::uint32_t k = begin; k < end; ++k) a += n.region_acceleration[n.member_index[k]];
        n.fluid_acceleration[s] = end > begin ? a / Real(end - begin) : a;
    });
}

// Once a step, before PCISPH, with n.force the last step's: o per node, the whole acceleration of
// the last step (the solve's first guess, `warm`), and the velocity it starts this step with.
inline void measure_node_accelerations(const DeviceContext& device, const NodeResponse n, View<const Vec3> velocity,
                                       Vec3* other, Vec3* warm, Vec3* last_velocity, Vec3 gravity, Real last_dt) {
    node_fluid_accelerations(device, n, n.force);
    parallel_for(device, "strong_coupling_nodes_measure", n.ibp_count, [=] MW_HD(std::size_t s) {
        if (!n.params[n.slot_object[s]].nodal) return;
        const Vec3 v = velocity[n.store_of_slot[s]];
        const Vec3 total = last_dt > Real(0) ? (Real(1) / last_dt) * (v - last_velocity[s]) : gravity + n.fluid_acceleration[s];
        other[s] = total - n.fluid_acceleration[s];
        warm[s] = total;
        last_velocity[s] = v;
    });
}

// Each SBP of a cloth: its corners' expected accelerations (their GPs' linked nodes).
inline void interpolate_node_responses(const DeviceContext& device, const NodeResponse n, Vec3* accel) {
    parallel_for(device, "strong_coupling_nodes_sbp", n.sbp_count, [=] MW_HD(std::size_t k) {
        if (!n.params[n.slot_object[n.ibp_count + k]].nodal) return;
        const SbpLink link = n.sbp[k];
        const Real b[3] = {link.bary.x, link.bary.y, link.bary.z};
        Vec3 a{0, 0, 0};
        for (int c = 0; c < 3; ++c)
            for (std::uint32_t e = n.gp_offsets[link.corner[c]]; e < n.gp_offsets[link.corner[c] + 1]; ++e)
                a += (b[c] * n.gp_weights[e]) * accel[n.gp_links[e]];
        accel[n.ibp_count + k] = a;
    });
}

// A new try: every node expected to move as in the last step (`warm`), the SBPs after them (each
// cloth's ω starts again with the rigid objects', start_object_responses).
inline void start_node_responses(const DeviceContext& device, const NodeResponse n, const Vec3* warm, Vec3* accel) {
    parallel_for(device, "strong_coupling_nodes_start", n.ibp_count, [=] MW_HD(std::size_t s) {
        if (!n.params[n.slot_object[s]].nodal) return;
        accel[s] = n.pinned[s] ? Vec3{0, 0, 0} : warm[s];
        n.last_residual[s] = Vec3{0, 0, 0};
    });
    interpolate_node_responses(device, n, accel);
}

// One iteration's update of the cloths' expected accelerations: `accel` (met by this iteration)
// into `next`, from this iteration's forces (n.force).
inline void relax_node_accelerations(const DeviceContext& device, const NodeResponse n, View<const Vec3> position,
                                     View<const Vec3> velocity, ResponseStep step, const Vec3* accel, Vec3* next) {
    node_fluid_accelerations(device, n, n.force);
    parallel_for(device, "strong_coupling_nodes_target", n.ibp_count, [=] MW_HD(std::size_t s) {
        const LsmObjectParams params = n.params[n.slot_object[s]];
        if (!params.nodal) return;
        Vec3 target{0, 0, 0};
        if (!n.pinned[s]) {
            target = n.other[s] + n.fluid_acceleration[s];
            // The walls: the node's shift dt (v + dt a) stays inside the box shrunk by its margin.
            const std::uint32_t i = n.store_of_slot[s];
            target = bounded_by_walls(target, velocity[i], position[i], position[i], params.wall_margin, step);
        }
        n.target_residual[s] = target - accel[s];
    });
    parallel_for(device, "strong_coupling_nodes_aitken", n.object_count, [=] MW_HD(std::size_t o) {
        if (!n.params[o].nodal) return;
        ResponseRelaxation& state = n.relaxation[o];
        Real omega = kFirstRelaxation;
        if (state.omega > Real(0)) {
            double dot_sum = 0, d2_sum = 0;
            for (std::uint32_t s = n.object_begin[o]; s < n.object_begin[o + 1]; ++s) {
                const Vec3 d = n.target_residual[s] - n.last_residual[s];
                dot_sum += double(dot(n.last_residual[s], d));
                d2_sum += double(norm2(d));
            }
            omega = d2_sum > 0 ? Real(-double(state.omega) * dot_sum / d2_sum) : state.omega;
            omega = omega < kMinRelaxation ? kMinRelaxation : omega > Real(1) ? Real(1) : omega;
        }
        state.omega = omega;
    });
    parallel_for(device, "strong_coupling_nodes_update", n.ibp_count, [=] MW_HD(std::size_t s) {
        if (!n.params[n.slot_object[s]].nodal) return;
        const Vec3 r = n.target_residual[s];
        next[s] = accel[s] + n.relaxation[n.slot_object[s]].omega * r;
        n.last_residual[s] = r;
    });
    interpolate_node_responses(device, n, next);
}

MW_BACKEND_END
