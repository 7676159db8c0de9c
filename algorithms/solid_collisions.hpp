// Contact between moving solids (docs/contact.md): after each LSM substep's update and the walls,
// two IBPs of different objects closer than the sum of their margins (r0: each lattice's outer
// IBPs lie about r0/2 inside its surface) are a contact, with normal n along the line between
// them and penetration the margins' sum less their distance.
//
// The solve is Jacobi over the contacts with mass splitting (every IBP gathers its contacts;
// nothing races, nothing depends on order): a contact's inelastic impulse j n, with
// j = max(0, -u·n) / (W_a + W_b) for the pair's relative velocity u, takes their approach to zero
// if it were alone; W is what an impulse at the IBP does to its velocity along n, times the
// number of contacts sharing it (an elastic IBP: its own contacts, over its mass; a rigid object's
// IBP: the whole body's contacts, times 1/M + n·((I⁻¹(r × n)) × r)), so that the contacts of one
// body together do not overshoot. Friction takes a share, the mean of the two objects'
// wall_friction, of the pair's sliding the same way. Both IBPs of a pair compute the same j from
// the same numbers (the pair's differences change sign exactly) and take ±j n: momentum is
// exchanged, never made. An elastic IBP's velocity changes by its impulse over its mass; a rigid
// object's by the body's: ΔV = ΣJ/M, Δω = I⁻¹ Σ r × J. The IBP moves by Δt times its velocity's
// change (its position already holds this substep's velocity). After kCollisionIterations such
// sweeps, one sweep of the same split on the penetration left (pseudo-impulses j = p / (W_a + W_b),
// moving positions only) takes overlapping objects apart.
//
// Pairs are found around the cells the IBPs were sorted into at the step's start
// (GridView::for_each_solid_around_particle): either IBP of a pair sees the other, or neither.
#pragma once
#include <cstdint>

#include <vector>

#include "algorithms/boundary_params.hpp"
#include "algorithms/lsm.hpp"
#include "algorithms/neighbor_grid.hpp"
#include "algorithms/wall_contact.hpp"

MW_BACKEND_BEGIN

// A rigid object's body for the contacts: its anchor (the first IBP's position), centre from the
// anchor, inverse inertia, mass and number of contacts.
struct CollisionBody {
    Vec3 anchor{0, 0, 0}, centre{0, 0, 0};
    SymMat3 inverse_inertia{0, 0, 0, 0, 0, 0};
    Real mass = 0;
    std::uint32_t contacts = 0;
};

struct SolidCollisionData {
    LsmData lsm;
    GridView grid;
    const std::int32_t* solid_slot = nullptr;     // by store index
    SolidObstacles obstacles;                     // with the domain walls
    const std::uint32_t* object_ibp_begin = nullptr;
    std::uint32_t object_count = 0;
    std::uint32_t* contacts = nullptr;  // per IBP slot
    Vec3* impulse = nullptr;            // per IBP slot, this sweep's
    CollisionBody* body = nullptr;      // per object (rigid ones)
};

// The IBP slot of store particle j when it is another moving object's unmelted IBP; -1 otherwise.
// (A melting object's outer lattice vertices are IBP slots with the SBP type: the slot decides.)
MW_INLINE std::int32_t other_ibp(const SolidCollisionData& c, std::uint32_t j, std::int32_t object) {
    const std::int32_t t = c.solid_slot[j];
    if (t < 0 || std::uint32_t(t) >= c.lsm.ibp_count || c.lsm.object[t] == object) return -1;
    return t;
}

// What a unit impulse along n at IBP slot s (store index i) does to its velocity along n, times
// the contacts sharing it; 0 for a pinned IBP (infinitely heavy).
MW_INLINE Real split_inverse_mass(const SolidCollisionData& c, std::uint32_t s, std::uint32_t i, Vec3 n) {
    if (c.lsm.pinned[s]) return Real(0);
    const std::int32_t o = c.lsm.object[s];
    if (!c.lsm.objects[o].rigid) return Real(c.contacts[s]) / c.lsm.mass[s];
    const CollisionBody b = c.body[o];
    if (!(b.mass > Real(0))) return Real(0);
    const Vec3 r = (c.lsm.position[i] - b.anchor) - b.centre;
    return Real(b.contacts) * (Real(1) / b.mass + dot(n, cross(b.inverse_inertia * cross(r, n), r)));
}

// Contacts are found a little early, at up to kContactSlop r0 apart (speculative contacts): a
// pair or an IBP and an obstacle that are apart by a gap g may still close at g/Δt, no more, so
// that a body resting on another, or on the floor, is in the solve before it sinks into it.
constexpr double kContactSlop = 0.1;

// The pair (s at x, store index i; t at store index j): true, with the unit normal from t to s
// and the gap (negative: penetration), when they are a contact.
MW_INLINE bool pair_contact(const SolidCollisionData& c, Vec3 x, Real reach, std::uint32_t j, Vec3& n, Real& gap) {
    const Vec3 between = x - c.lsm.position[j];
    const Real distance2 = norm2(between);
    const Real seen = reach + Real(kContactSlop) * reach;
    if (!(distance2 < seen * seen) || !(distance2 > Real(0))) return false;
    const Real distance = std::sqrt(distance2);
    n = (Real(1) / distance) * between;
    gap = distance - reach;
    return true;
}

// The IBP at x against the walls and static obstacles: true, with the normal and the gap, when
// it is a contact.
MW_INLINE bool obstacle_contact(const SolidCollisionData& c, Vec3 x, const LsmObjectParams& object, Vec3& n, Real& gap) {
    const Real slop = Real(2 * kContactSlop) * object.margin;
    Real depth = 0;
    if (!c.obstacles.deepest_with_walls(x, object.wall_margin + slop, object.margin + slop, n, depth)) return false;
    gap = slop - depth;
    return true;
}

// The impulse (over Δt for positions) that a contact with gap `gap`, normal n and relative
// velocity u takes under the split inverse masses w: velocities, the approach beyond what the gap
// allows in Δt, and a share `friction` of the sliding; positions, the penetration.
MW_INLINE Vec3 contact_impulse(Vec3 u, Vec3 n, Real gap, Real w, Real friction, Real dt, bool positions) {
    if (positions) return gap < Real(0) ? (-gap / (dt * w)) * n : Vec3{0, 0, 0};
    const Real allowed = gap > Real(0) ? gap / dt : Real(0);
    const Real un = dot(u, n);
    if (!(un < -allowed)) return Vec3{0, 0, 0};
    return ((-allowed - un) / w) * n - (friction / w) * (u - un * n);
}

// Each IBP's contacts (c.contacts) and each rigid object's body; returns how many contacts there
// are in all (one reduction read back: with none, the sweeps are skipped).
inline std::uint64_t count_solid_contacts(const DeviceContext& device, const SolidCollisionData c) {
    parallel_for(device, "solid_contact_count", c.lsm.ibp_count, [=] MW_HD(std::size_t si) {
        const std::uint32_t s = static_cast<std::uint32_t>(si);
        const std::uint32_t i = c.lsm.store_of_slot[s];
        std::uint32_t count = 0;
        if (i != kMeltedSlot) {
            const std::int32_t object = c.lsm.object[s];
            const Vec3 x = c.lsm.position[i];
            const Real margin = c.lsm.objects[object].margin;
            Vec3 n{0, 0, 0};
            Real gap = 0;
            c.grid.for_each_solid_around_particle(i, [&](std::uint32_t j) {
                const std::int32_t t = other_ibp(c, j, object);
                if (t >= 0 && pair_contact(c, x, margin + c.lsm.objects[c.lsm.object[t]].margin, j, n, gap)) ++count;
            });
            if (obstacle_contact(c, x, c.lsm.objects[object], n, gap)) ++count;
        }
        c.contacts[s] = count;
    });
    const std::uint32_t* contacts = c.contacts;
    const std::uint64_t total = transform_reduce(device, "solid_contact_total", c.lsm.ibp_count, std::uint64_t(0), SumOp{},
                                                 [=] MW_HD(std::size_t s) { return std::uint64_t(contacts[s]); });
    if (total == 0) return 0;
    // Each rigid object's body (one thread per object, its IBPs in slot order: deterministic).
    parallel_for(device, "solid_contact_bodies", c.object_count, [=] MW_HD(std::size_t o) {
        CollisionBody b;
        if (c.lsm.objects[o].rigid) {
            BodySums sums;
            bool anchored = false, pinned = false;
            for (std::uint32_t s = c.object_ibp_begin[o]; s < c.object_ibp_begin[o + 1]; ++s) {
                const std::uint32_t i = c.lsm.store_of_slot[s];
                if (i == kMeltedSlot) continue;
                if (!anchored) b.anchor = c.lsm.position[i], anchored = true;
                pinned = pinned || c.lsm.pinned[s];
                sums.add(c.lsm.mass[s], c.lsm.position[i] - b.anchor, Vec3{0, 0, 0});
                b.contacts += c.contacts[s];
            }
            // A pinned rigid object is held in place: infinitely heavy (mass 0 here).
            if (sums.M > Real(0) && !pinned) {
                const BodyMotion m = body_motion(sums);
                b.centre = m.centre;
                b.inverse_inertia = m.inverse_inertia;
                b.mass = sums.M;
            }
        }
        c.body[o] = b;
    });
    return total;
}

// One sweep: every IBP in contact gathers its contacts' impulses (`positions`: the
// pseudo-impulses on the penetration, over Δt so that both sweeps move an IBP by Δt J / m).
inline void gather_solid_impulses(const DeviceContext& device, const SolidCollisionData c, Real dt, bool positions) {
    parallel_for(device, "solid_contact_impulses", c.lsm.ibp_count, [=] MW_HD(std::size_t si) {
        const std::uint32_t s = static_cast<std::uint32_t>(si);
        Vec3 total{0, 0, 0};
        const std::uint32_t i = c.lsm.store_of_slot[s];
        if (c.contacts[s] != 0 && i != kMeltedSlot) {
            const std::int32_t object = c.lsm.object[s];
            const LsmObjectParams own = c.lsm.objects[object];
            const Vec3 x = c.lsm.position[i], v = c.lsm.velocity[i];
            Vec3 n{0, 0, 0};
            Real gap = 0;
            c.grid.for_each_solid_around_particle(i, [&](std::uint32_t j) {
                const std::int32_t t = other_ibp(c, j, object);
                // Both sides of a pair gather it or neither: an IBP counted out of contact at the
                // solve's start gathers nothing, so its partners leave it out too.
                if (t < 0 || c.contacts[t] == 0) return;
                const LsmObjectParams other = c.lsm.objects[c.lsm.object[t]];
                if (!pair_contact(c, x, own.margin + other.margin, j, n, gap)) return;
                const Real w = split_inverse_mass(c, s, i, n) + split_inverse_mass(c, std::uint32_t(t), j, n);
                if (w > Real(0))
                    total += contact_impulse(v - c.lsm.velocity[j], n, gap, w,
                                             Real(0.5) * (own.friction + other.friction), dt, positions);
            });
            // The walls and static obstacles, infinitely heavy: the same rules with W_b = 0.
            if (obstacle_contact(c, x, own, n, gap)) {
                const Real w = split_inverse_mass(c, s, i, n);
                if (w > Real(0)) total += contact_impulse(v, n, gap, w, own.friction, dt, positions);
            }
        }
        c.impulse[s] = total;
    });
}

// The sweep's impulses applied: elastic IBPs one by one, rigid objects as bodies.
inline void apply_solid_impulses(const DeviceContext& device, const SolidCollisionData c, Real dt, bool positions) {
    parallel_for(device, "solid_contact_elastic", c.lsm.ibp_count, [=] MW_HD(std::size_t si) {
        const std::uint32_t s = static_cast<std::uint32_t>(si);
        const std::uint32_t i = c.lsm.store_of_slot[s];
        if (i == kMeltedSlot || c.contacts[s] == 0 || c.lsm.pinned[s] || c.lsm.objects[c.lsm.object[s]].rigid) return;
        const Vec3 dv = (Real(1) / c.lsm.mass[s]) * c.impulse[s];
        if (!positions) c.lsm.velocity[i] += dv;
        c.lsm.position[i] += dt * dv;
    });
    parallel_for(device, "solid_contact_rigid", c.object_count, [=] MW_HD(std::size_t o) {
        const CollisionBody b = c.body[o];
        if (!c.lsm.objects[o].rigid || b.contacts == 0 || !(b.mass > Real(0))) return;
        Vec3 P{0, 0, 0}, L{0, 0, 0};
        for (std::uint32_t s = c.object_ibp_begin[o]; s < c.object_ibp_begin[o + 1]; ++s) {
            const std::uint32_t i = c.lsm.store_of_slot[s];
            if (i == kMeltedSlot || c.contacts[s] == 0) continue;
            if (c.lsm.pinned[s]) return;  // held in place
            P += c.impulse[s];
            L += cross((c.lsm.position[i] - b.anchor) - b.centre, c.impulse[s]);
        }
        const Vec3 dV = (Real(1) / b.mass) * P, dw = b.inverse_inertia * L;
        for (std::uint32_t s = c.object_ibp_begin[o]; s < c.object_ibp_begin[o + 1]; ++s) {
            const std::uint32_t i = c.lsm.store_of_slot[s];
            if (i == kMeltedSlot) continue;
            const Vec3 dv = dV + cross(dw, (c.lsm.position[i] - b.anchor) - b.centre);
            if (!positions) c.lsm.velocity[i] += dv;
            c.lsm.position[i] += dt * dv;
        }
        // The centre moves with the IBPs (Σ m dω × r = 0 about it): the next sweep's r about it
        // keeps Σ m r = 0, and the momentum the spin's change carries zero.
        c.body[o].centre = b.centre + dt * dV;
    });
}

// The whole contact stage of one substep of length dt. Without a contact the sweeps would change
// nothing (every IBP and body skips itself), and their 66 launches cost more than the count's
// read back: skipped.
inline void solid_collisions(const DeviceContext& device, const SolidCollisionData c, Real dt) {
    if (count_solid_contacts(device, c) == 0) return;
    for (int sweep = 0; sweep < kCollisionIterations; ++sweep) {
        gather_solid_impulses(device, c, dt, false);
        apply_solid_impulses(device, c, dt, false);
    }
    gather_solid_impulses(device, c, dt, true);
    apply_solid_impulses(device, c, dt, true);
}

// What the solids' contacts keep between substeps: the static obstacles in backend memory, the
// rigid objects' obstacle impulses, and the arrays of the contacts between solids. Owned by the
// solids module (solid_bodies.hpp).
class SolidContactState {
   public:
    // From the setup's parameters: the static boxes and mesh objects (scene builder), and whether
    // two moving objects can meet (`moving_objects` of them).
    void init(const SimulationParams& params, std::size_t ibp_count, std::size_t object_count, std::size_t moving_objects,
              bool has_rigid) {
        const BoundaryParams& boundary = params.boundary;
        // Solids stay inside the domain box whether or not walls line it (lsm.hpp).
        walls_ = true;
        wall_lo_ = params.domain_min;
        wall_hi_ = params.domain_max;
        open_along_z_in_2d(wall_lo_, wall_hi_, params.dimensions);
        std::vector<ContactBox> boxes;
        for (const StaticBoxFaces& b : boundary.static_boxes) boxes.push_back(ContactBox{b.lo, b.hi, Real(0)});
        boxes_.upload(boxes);
        objects_.upload(boundary.static_objects);
        object_distances_.upload(boundary.static_object_distances);
        obstacle_impulse_.assign(has_rigid ? ibp_count : 0, Real(0));
        between_solids_ = moving_objects > 1 && params.solver.solid_contact;
        contacts_.assign(between_solids_ ? ibp_count : 0, 0u);
        impulse_.assign(between_solids_ ? ibp_count : 0, Vec3{0, 0, 0});
        body_.assign(between_solids_ ? object_count : 0, CollisionBody{});
        object_count_ = object_count;
    }
    SolidObstacles obstacles() const {
        SolidObstacles o;
        o.boxes = boxes_.cview();
        o.objects = objects_.cview();
        o.object_distances = object_distances_.cview();
        return o;
    }
    Real* obstacle_impulse() { return obstacle_impulse_.view().data(); }
    bool between_solids() const { return between_solids_; }
    SolidCollisionData collisions(const LsmData& d, const GridView& grid,
                                  const DeviceArray<std::int32_t>& solid_slot, const std::uint32_t* object_ibp_begin) {
        SolidCollisionData c;
        c.obstacles = obstacles();
        c.obstacles.walls = walls_;
        c.obstacles.wall_lo = wall_lo_;
        c.obstacles.wall_hi = wall_hi_;
        c.lsm = d;
        c.grid = grid;
        c.solid_slot = solid_slot.cview().data();
        c.object_ibp_begin = object_ibp_begin;
        c.object_count = static_cast<std::uint32_t>(object_count_);
        c.contacts = contacts_.view().data();
        c.impulse = impulse_.view().data();
        c.body = body_.view().data();
        return c;
    }
    std::size_t bytes() const {
        return boxes_.bytes() + objects_.bytes() + object_distances_.bytes() + obstacle_impulse_.bytes() +
               contacts_.bytes() + impulse_.bytes() + body_.bytes();
    }

   private:
    DeviceArray<ContactBox> boxes_;
    DeviceArray<ContactField> objects_;
    DeviceArray<Real> object_distances_;
    DeviceArray<Real> obstacle_impulse_;  // per IBP of a rigid object, its obstacle contact's impulse
    bool between_solids_ = false;
    bool walls_ = false;
    Vec3 wall_lo_{0, 0, 0}, wall_hi_{0, 0, 0};
    std::size_t object_count_ = 0;
    DeviceArray<std::uint32_t> contacts_;  // per IBP
    DeviceArray<Vec3> impulse_;            // per IBP
    DeviceArray<CollisionBody> body_;      // per object
};

MW_BACKEND_END
