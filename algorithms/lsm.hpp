// Lattice shape matching, per-step part (device): region sums and rotations, then goals and the
// velocity/position update of every IBP. Data layout: lsm_regions.hpp; the class that owns the
// arrays and calls these stages: solid_bodies.hpp. The algebra (docs/method.md, "Lattice shape
// matching"), written in displacements u = x - x0 so that nothing cancels catastrophically in
// float and a body at rest stays bitwise at rest:
//   c_r = c0_r + ū_r,            ū_r = u_a + Σ m̃ (u - u_a) / M_r   (u_a: one member's, the anchor)
//   A_r = A0_r + Σ m̃ (u - u_a) qᵀ, q = x0 - c0_r, A0_r = Σ m̃ q qᵀ (precomputed, exactly symmetric;
//                                  Σ m̃ q = 0, so subtracting u_a changes nothing but rounding)
//   R_r = polar(A_r), warm-started from last step's R_r
//   g_i - x_i = mean_r [(R_r - I) q_ir + ū_r] - u_i
// Every kernel is a gather (each thread writes only its own region or particle): deterministic.
#pragma once
#include <cmath>

#include "algorithms/lsm_regions.hpp"
#include "algorithms/solid_obstacles.hpp"
#include "algorithms/polar_decomposition.hpp"
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

// The inner particles' kinetic energy, top speed and first non-finite slot after an LSM step.
struct SolidSummary {
    double kinetic_energy = 0;
    Real max_speed2 = 0;
    std::uint32_t first_bad = 0xffffffffu;  // slot of the first non-finite IBP
};

// Sums over members of one region, relative to its anchor (see the top of the file): su = Σ m̃ (u
// - u_a), Au = Σ m̃ (u - u_a) qᵀ; for damped objects sv = Σ m̃ v and sl = Σ m̃ (x - c0) × v; for
// objects whose forces act through the regions, sf = Σ f̃ and sτ = Σ (x - c0) × f̃, with f̃ = f / (the
// IBP's number of regions).
struct RegionSums {
    Vec3 su, sv, sl, sf, st;
    Mat3 Au;
};

// Raw device pointers of the LSM state, captured by value in kernels.
struct LsmData {
    // The particle store (positions and velocities of all particles) and the slot map.
    Vec3* position = nullptr;
    Vec3* velocity = nullptr;
    const std::uint32_t* store_of_slot = nullptr;
    // IBPs (slots 0 .. ibp_count)
    std::uint32_t ibp_count = 0;
    const Vec3* rest = nullptr;
    const Real* mass = nullptr;
    const Real* split_mass = nullptr;
    const std::int32_t* object = nullptr;
    const std::uint8_t* pinned = nullptr;
    const std::uint32_t* regions_begin = nullptr;
    const std::uint32_t* regions_end = nullptr;
    // External forces (the two-way coupling's, per IBP), applied through the regions: with
    // `forces`, each region moves as a rigid body under its members' forces (their total and
    // torque; each IBP's force split among its regions, as its mass is), and an IBP takes the mean
    // of its regions' accelerations at its position, not its own force over its own mass. A rigid
    // object is then a rigid body under its forces, and momentum and angular momentum are kept.
    // The coupling's forces land on the surface IBPs only; taken one IBP at a time they made a
    // rigid box in a pool blow up within 15 steps and an elastic cube hit by fluid gain energy
    // without bound (docs/coupling.md).
    bool forces = false;
    const Vec3* force = nullptr;
    Vec3* displacement = nullptr;  // u = x - x0 per IBP, this step's (the region sums read it)
    Mat3* mean_rotation = nullptr;  // average rotation of the IBP's regions (for Eq. 19)
    // Regions
    std::uint32_t region_count = 0;
    const std::uint32_t* region_offsets = nullptr;
    const std::uint32_t* region_end = nullptr;  // one past each region's last member (lsm_regions.hpp)
    const std::uint32_t* member_index = nullptr;
    const Real* region_mass = nullptr;
    const Vec3* region_c0 = nullptr;
    const SymMat3* region_A0 = nullptr;
    const SymMat3* region_inertia_inv = nullptr;
    const std::int32_t* region_object = nullptr;
    // Chunked sums of large regions (lsm_regions.hpp, LsmHostLayout); chunk_count 0: none
    std::uint32_t chunk_count = 0;
    const std::uint32_t* region_chunks = nullptr;
    const std::uint32_t* chunk_begin = nullptr;
    const std::uint32_t* chunk_region = nullptr;
    RegionSums* chunk_sums = nullptr;
    Quat* rotation = nullptr;         // R_r, the warm start of next step's polar decomposition
    Mat3* rotation_matrix = nullptr;  // the same R_r as a matrix, for the per-IBP goals
    Vec3* mean_displacement = nullptr;
    Vec3* region_velocity = nullptr;  // only written for objects with damping
    Vec3* region_omega = nullptr;
    // Only with `forces`: each region's acceleration under its IBPs' (split) forces, linear, and
    // angular about its centre of mass c0 + ū.
    Vec3* region_acceleration = nullptr;
    Vec3* region_angular_acceleration = nullptr;
    const LsmObjectParams* objects = nullptr;
};

struct LsmStepParams {
    Real dt = 0;
    Vec3 gravity{0, 0, 0};
    Vec3 domain_min{0, 0, 0}, domain_max{0, 0, 0};
    SolidObstacles obstacles;  // static boxes and mesh objects (solid_obstacles.hpp)
};

// Sweeps of an elastic IBP over its deepest obstacle contact (an IBP in a stair's inner corner
// meets a tread and a riser).
constexpr int kObstacleSweeps = 2;

// An elastic IBP (or a cloth node) at the obstacles: out to the margin along the deepest contact's
// normal, its velocity into the obstacle dropped and a share `friction` of its sliding removed,
// as at a domain wall.
MW_INLINE void keep_out_of_obstacles(const SolidObstacles& obstacles, Real margin, Real object_margin, Real friction, Vec3& x,
                                     Vec3& v) {
    for (int sweep = 0; sweep < kObstacleSweeps; ++sweep) {
        Vec3 n{0, 0, 0};
        Real depth = 0;
        if (!obstacles.deepest(x, margin, object_margin, n, depth)) return;
        x += depth * n;
        const Real vn = dot(v, n);
        const Vec3 normal = vn < Real(0) ? Vec3{0, 0, 0} : vn * n;
        v = normal + (Real(1) - friction) * (v - vn * n);
    }
}

// Displacements are taken relative to one member's (the anchor's, the region's first): a
// translation of the region then gives exactly zero sums, and ū exactly the translation.
MW_INLINE Vec3 region_anchor_displacement(const LsmData& d, std::uint32_t r) {
    return d.displacement[d.member_index[d.region_offsets[r]]];
}

MW_INLINE RegionSums sum_region_members(const LsmData& d, std::uint32_t begin, std::uint32_t end, Vec3 c0, Vec3 ua,
                                        bool damp, bool forces) {
    RegionSums S{{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, mat3_zero()};
    for (std::uint32_t k = begin; k < end; ++k) {
        const std::uint32_t s = d.member_index[k];
        const Real m = d.split_mass[s];
        const Vec3 x0 = d.rest[s];
        const Vec3 mu = m * (d.displacement[s] - ua);
        const Vec3 q = x0 - c0;
        S.su += mu;
        S.Au.m[0][0] += mu.x * q.x, S.Au.m[0][1] += mu.x * q.y, S.Au.m[0][2] += mu.x * q.z;
        S.Au.m[1][0] += mu.y * q.x, S.Au.m[1][1] += mu.y * q.y, S.Au.m[1][2] += mu.y * q.z;
        S.Au.m[2][0] += mu.z * q.x, S.Au.m[2][1] += mu.z * q.y, S.Au.m[2][2] += mu.z * q.z;
        if (damp) {
            const std::uint32_t i = d.store_of_slot[s];
            const Vec3 mv = m * d.velocity[i];
            S.sv += mv;
            S.sl += cross(d.position[i] - c0, mv);
        }
        if (forces) {
            // Each IBP's force is split among its regions, as its mass is.
            const Vec3 f = d.force[s] / Real(d.regions_end[s] - d.regions_begin[s]);
            S.sf += f;
            S.st += cross(d.position[d.store_of_slot[s]] - c0, f);
        }
    }
    return S;
}

MW_INLINE bool region_damped(const LsmData& d, std::uint32_t r) {
    return d.objects[d.region_object[r]].damping_rate > Real(0);
}

// Region sums, rotation (warm-started polar decomposition) and, for damped objects, the region's
// rigid velocity (linear velocity V and angular velocity ω = I⁻¹ L, with the rest inertia
// rotated by R). A region of more than kRegionSerialMembers (a rigid body) would leave one thread
// looping over all its members; it is summed in chunks first, in a fixed order (deterministic).
inline void lsm_region_update(const DeviceContext& device, const LsmData d) {
    // u = x - x0 once per IBP, in slot order: each is read by about (2w + 1)^3 regions.
    parallel_for(device, "lsm_displacements", d.ibp_count, [=] MW_HD(std::size_t s) {
        const std::uint32_t i = d.store_of_slot[s];
        if (i != kMeltedSlot) d.displacement[s] = d.position[i] - d.rest[s];
    });
    parallel_for(device, "lsm_region_chunks", d.chunk_count, [=] MW_HD(std::size_t c) {
        const std::uint32_t r = d.chunk_region[c];
        const std::uint32_t end = c + 1 < d.region_chunks[r + 1] ? d.chunk_begin[c + 1] : d.region_end[r];
        d.chunk_sums[c] = sum_region_members(d, d.chunk_begin[c], end, d.region_c0[r],
                                             region_anchor_displacement(d, r), region_damped(d, r), d.forces);
    });
    parallel_for(device, "lsm_regions", d.region_count, [=] MW_HD(std::size_t r) {
        const std::uint32_t begin = d.region_offsets[r], end = d.region_end[r];
        if (begin == end) return;  // a melted particle's
        const Real M = d.region_mass[r];
        const Vec3 c0 = d.region_c0[r];
        const bool damp = region_damped(d, std::uint32_t(r));
        const Vec3 ua = region_anchor_displacement(d, std::uint32_t(r));
        const std::uint32_t chunks_begin = d.chunk_count ? d.region_chunks[r] : 0u;
        const std::uint32_t chunks_end = d.chunk_count ? d.region_chunks[r + 1] : 0u;
        RegionSums S;
        if (chunks_begin == chunks_end) {
            S = sum_region_members(d, begin, end, c0, ua, damp, d.forces);
        } else {
            S = d.chunk_sums[chunks_begin];
            for (std::uint32_t c = chunks_begin + 1; c < chunks_end; ++c) {
                const RegionSums& part = d.chunk_sums[c];
                S.su += part.su, S.sv += part.sv, S.sl += part.sl, S.sf += part.sf, S.st += part.st;
                S.Au = S.Au + part.Au;
            }
        }
        const Mat3 A = sym_to_mat3(d.region_A0[r]) + S.Au;
        const Quat R = polar_rotation(A, d.rotation[r]);
        d.rotation[r] = R;
        // Converted once per region here rather than once per (IBP, region) pair in the goals,
        // where it would be the largest cost of an elastic step (about 125 pairs per IBP at w = 2).
        d.rotation_matrix[r] = quat_to_mat3(R);
        const Vec3 ubar = ua + S.su / M;
        d.mean_displacement[r] = ubar;
        if (damp) {
            // L about c = c0 + ū: Σ m (x - c) × v = Σ m (x - c0) × v - ū × Σ m v.
            const Vec3 L = S.sl - cross(ubar, S.sv);
            const Quat Rinv{R.w, -R.x, -R.y, -R.z};
            d.region_velocity[r] = S.sv / M;
            d.region_omega[r] = quat_rotate(R, d.region_inertia_inv[r] * quat_rotate(Rinv, L));
        }
        if (d.forces) {
            // Newton and Euler for the region as a rigid body (the gyroscopic term ω × Iω is left
            // to the shape matching, which carries the rotation): a = F/M, dω/dt = I⁻¹ τ about
            // c = c0 + ū. Summed over every IBP's mean of its regions, m (a + dω/dt × (x - c)) gives
            // back the total force and torque: momentum and angular momentum are kept.
            const Vec3 torque = S.st - cross(ubar, S.sf);
            const Quat Rinv{R.w, -R.x, -R.y, -R.z};
            d.region_acceleration[r] = S.sf / M;
            d.region_angular_acceleration[r] = quat_rotate(R, d.region_inertia_inv[r] * quat_rotate(Rinv, torque));
        }
    });
}

// g_i - x_i for IBP slot s at position x with velocity v (see the top of the file); also the
// mean rotation of its regions, when `damp` the mean over its regions of their rigid velocity at
// x, minus v, and with d.forces the mean of their rigid acceleration at x (external forces). Each region's term is formed as a difference before averaging: averaging large
// equal values (a translated body's ū) and subtracting afterwards rounds the same way for every
// particle, which shows up as a slow spurious acceleration.
MW_INLINE Vec3 lsm_goal_offset(const LsmData& d, std::uint32_t s, Vec3 x, Vec3 v, Mat3& mean_rotation, bool damp,
                               Vec3& rigid_velocity_offset, Vec3& external_acceleration) {
    const Vec3 x0 = d.rest[s];
    const Vec3 u = x - x0;
    const std::uint32_t begin = d.regions_begin[s], end = d.regions_end[s];
    Vec3 sum{0, 0, 0}, vr{0, 0, 0}, ar{0, 0, 0};
    Mat3 rsum = mat3_zero();
    for (std::uint32_t k = begin; k < end; ++k) {
        const std::uint32_t r = d.member_index[k];
        const Mat3 R = d.rotation_matrix[r];
        const Vec3 c0 = d.region_c0[r];
        const Vec3 ubar = d.mean_displacement[r];
        const Vec3 q = x0 - c0;
        sum += (R * q - q) + (ubar - u);
        rsum = rsum + R;
        if (damp) vr += (d.region_velocity[r] - v) + cross(d.region_omega[r], x - (c0 + ubar));
        if (d.forces) ar += d.region_acceleration[r] + cross(d.region_angular_acceleration[r], x - (c0 + ubar));
    }
    const Real inv = end > begin ? Real(1) / Real(end - begin) : Real(0);
    mean_rotation = inv * rsum;
    rigid_velocity_offset = inv * vr;
    external_acceleration = inv * ar;
    return inv * sum;
}

// The IBP update: v += α (g - x)/Δt + Δt (a_ext + gravity) (after damping), x += Δt v, then the
// domain walls, IBP by IBP for an elastic object (a rigid one meets them whole: lsm_rigid_walls);
// pinned IBPs stay at their rest position with zero velocity.
inline void lsm_particle_update(const DeviceContext& device, const LsmData d, const LsmStepParams p) {
    parallel_for(device, "lsm_update", d.ibp_count, [=] MW_HD(std::size_t si) {
        const std::uint32_t s = static_cast<std::uint32_t>(si);
        const std::uint32_t i = d.store_of_slot[s];
        if (i == kMeltedSlot) return;  // now fluid (melting.hpp)
        const LsmObjectParams obj = d.objects[d.object[s]];
        Vec3 x = d.position[i];
        Vec3 v = d.velocity[i];
        const bool damp = obj.damping_rate > Real(0);
        Mat3 mean_rotation;
        Vec3 rigid_offset, external;
        const Vec3 offset = lsm_goal_offset(d, s, x, v, mean_rotation, damp, rigid_offset, external);
        d.mean_rotation[s] = mean_rotation;
        if (d.pinned[s]) {
            d.position[i] = d.rest[s];
            d.velocity[i] = Vec3{0, 0, 0};
            return;
        }
        if (damp) {
            // v <- v_rigid + e^(-k Δt) (v - v_rigid)
            v += (Real(1) - std::exp(-obj.damping_rate * p.dt)) * rigid_offset;
        }
        v += (obj.alpha / p.dt) * offset + p.dt * (external + p.gravity);
        x += p.dt * v;
        if (obj.rigid) {  // the walls meet the whole body: lsm_rigid_walls
            d.position[i] = x;
            d.velocity[i] = v;
            return;
        }
        if (p.obstacles.any()) keep_out_of_obstacles(p.obstacles, obj.wall_margin, obj.margin, obj.friction, x, v);
        // Domain walls: clamp into the box shrunk by the margin, drop the outward normal velocity,
        // scale the tangential velocity by (1 - friction) on each wall touched.
        const Real lo[3] = {p.domain_min.x + obj.wall_margin, p.domain_min.y + obj.wall_margin, p.domain_min.z + obj.wall_margin};
        const Real hi[3] = {p.domain_max.x - obj.wall_margin, p.domain_max.y - obj.wall_margin, p.domain_max.z - obj.wall_margin};
        Real* xc[3] = {&x.x, &x.y, &x.z};
        Real* vc[3] = {&v.x, &v.y, &v.z};
        for (int a = 0; a < 3; ++a) {
            int side = 0;
            if (*xc[a] < lo[a]) {
                *xc[a] = lo[a];
                if (*vc[a] < Real(0)) *vc[a] = Real(0);
                side = 1;
            } else if (*xc[a] > hi[a]) {
                *xc[a] = hi[a];
                if (*vc[a] > Real(0)) *vc[a] = Real(0);
                side = 1;
            }
            if (side) {
                const Real keep = Real(1) - obj.friction;
                for (int b = 0; b < 3; ++b)
                    if (b != a) *vc[b] *= keep;
            }
        }
        d.position[i] = x;
        d.velocity[i] = v;
    });
}

// A body's IBPs summed relative to an anchor IBP (so that float keeps the body's size, not its
// place): mass, first moment, momentum, moment of momentum and inertia Σ m (|r|² E - r rᵀ).
struct BodySums {
    Real M = 0;
    Vec3 first_moment{0, 0, 0}, momentum{0, 0, 0}, moment_of_momentum{0, 0, 0};
    Real ixx = 0, iyy = 0, izz = 0, ixy = 0, ixz = 0, iyz = 0;
    MW_INLINE void add(Real m, Vec3 r, Vec3 v) {
        M += m;
        first_moment += m * r;
        momentum += m * v;
        moment_of_momentum += m * cross(r, v);
        ixx += m * (r.y * r.y + r.z * r.z), iyy += m * (r.x * r.x + r.z * r.z), izz += m * (r.x * r.x + r.y * r.y);
        ixy -= m * r.x * r.y, ixz -= m * r.x * r.z, iyz -= m * r.y * r.z;
    }
};

// The body's rigid motion: its centre c (from the anchor), velocity V and spin ω = I⁻¹ L about c
// (parallel axis theorem: I_c = I_anchor - M (|c|² E - c cᵀ), L_c = L_anchor - c × P). M > 0.
// `anchor` is the caller's to keep with it (lsm_body_damping).
struct BodyMotion {
    Vec3 anchor{0, 0, 0}, centre{0, 0, 0}, velocity{0, 0, 0}, spin{0, 0, 0};
    SymMat3 inverse_inertia{0, 0, 0, 0, 0, 0};
};
MW_INLINE BodyMotion body_motion(const BodySums& b) {
    BodyMotion m;
    const Vec3 c = b.first_moment / b.M;
    m.centre = c;
    m.velocity = b.momentum / b.M;
    const Vec3 L = b.moment_of_momentum - cross(c, b.momentum);
    m.inverse_inertia = lsm_detail::regularised_inverse(
        double(b.ixx - b.M * (c.y * c.y + c.z * c.z)), double(b.iyy - b.M * (c.x * c.x + c.z * c.z)),
        double(b.izz - b.M * (c.x * c.x + c.y * c.y)), double(b.ixy + b.M * c.x * c.y), double(b.ixz + b.M * c.x * c.z),
        double(b.iyz + b.M * c.y * c.z));
    m.spin = m.inverse_inertia * L;
    return m;
}

// Sweeps over a rigid object's contacts with the walls (lsm_rigid_walls).
constexpr int kRigidWallSweeps = 8;

MW_INLINE Real component(Vec3 v, int axis) { return axis == 0 ? v.x : axis == 1 ? v.y : v.z; }
MW_INLINE Vec3 axis_vector(int axis, Real length) {
    return Vec3{axis == 0 ? length : Real(0), axis == 1 ? length : Real(0), axis == 2 ? length : Real(0)};
}

// A rigid object at the domain walls, as one body (after lsm_particle_update; one thread per
// object, its IBPs in slot order: deterministic). Every IBP past a wall (past its wall margin, as
// for elastic objects: r0/2, or 2 r0 with the walls' film) is a contact. Through the body's mass and inertia, inelastic impulses at
// the contacts take the body's velocity into the walls there to zero, so a box landing on a
// corner turns down onto a face and rests on all of it; friction takes a share `friction` of the
// body's sliding along each wall touched (as an elastic object's IBPs lose theirs). Then the
// whole body moves out by each wall's deepest IBP, and every IBP takes the body's velocity at its
// place: no IBP moves apart from the body's rigid motion. `wall_impulse` (one per IBP) holds the
// contacts' impulses while they are summed.
// Clamped IBP by IBP, a rigid box thrown against the ceiling was squashed against it (the shape
// matching of the next step fits the squashed shape, which the walls squash again).
inline void lsm_rigid_walls(const DeviceContext& device, const LsmData d, const LsmStepParams p,
                            const std::uint32_t* object_ibp_begin, std::size_t object_count, Vec3* wall_impulse,
                            Real* obstacle_impulse) {
    parallel_for(device, "lsm_rigid_walls", object_count, [=] MW_HD(std::size_t o) {
        const LsmObjectParams obj = d.objects[o];
        if (!obj.rigid) return;
        const Vec3 lo = p.domain_min + Vec3{obj.wall_margin, obj.wall_margin, obj.wall_margin};
        const Vec3 hi = p.domain_max - Vec3{obj.wall_margin, obj.wall_margin, obj.wall_margin};
        // Walls 2a (the low face of axis a, normal +e_a) and 2a + 1 (the high face, normal -e_a):
        // how deep the deepest IBP is past each (0: none). The body's sums are taken relative to
        // an anchor IBP, so that float keeps the body's size, not its place.
        Real depth[6] = {0, 0, 0, 0, 0, 0};
        Vec3 anchor{0, 0, 0};
        bool anchored = false, touching = false;
        BodySums body;
        for (std::uint32_t s = object_ibp_begin[o]; s < object_ibp_begin[o + 1]; ++s) {
            const std::uint32_t i = d.store_of_slot[s];
            if (i == kMeltedSlot) continue;
            if (d.pinned[s]) return;  // held in place: the walls have nothing to move
            const Vec3 x = d.position[i];
            if (!anchored) anchor = x, anchored = true;
            const Vec3 r = x - anchor;
            for (int a = 0; a < 3; ++a) {
                const Real below = component(lo, a) - component(x, a), above = component(x, a) - component(hi, a);
                if (below > depth[2 * a]) depth[2 * a] = below;
                if (above > depth[2 * a + 1]) depth[2 * a + 1] = above;
                touching = touching || below > Real(0) || above > Real(0);
            }
            Vec3 n{0, 0, 0};
            Real obstacle_depth = 0;
            touching = touching || p.obstacles.deepest(x, obj.wall_margin, obj.margin, n, obstacle_depth);
            body.add(d.mass[s], r, d.velocity[i]);
        }
        if (!touching || !(body.M > Real(0)) || !is_finite(body.momentum)) return;  // non-finite values are the guard's
        const BodyMotion motion = body_motion(body);
        const Real M = body.M;
        const Vec3 c = motion.centre;
        const SymMat3 inverse_inertia = motion.inverse_inertia;
        Vec3 V = motion.velocity, omega = motion.spin;
        // Every IBP past a wall is a contact. Its impulse along the wall's normal n, accumulated
        // over sweeps of the contacts in slot order and never negative (a wall pushes, never
        // pulls), is what takes the body's velocity into the wall there to zero: the velocity at
        // r from c along n changes by j (1/M + n · ((I⁻¹ (r × n)) × r)) for an impulse j. A box on
        // a face so rests on the whole face; met at one point a step, the mean of the IBPs past a
        // wall, it rocked about that point.
        for (std::uint32_t s = object_ibp_begin[o]; s < object_ibp_begin[o + 1]; ++s) {
            wall_impulse[s] = Vec3{0, 0, 0};
            obstacle_impulse[s] = Real(0);
        }
        for (int sweep = 0; sweep < kRigidWallSweeps; ++sweep) {
            for (std::uint32_t s = object_ibp_begin[o]; s < object_ibp_begin[o + 1]; ++s) {
                const std::uint32_t i = d.store_of_slot[s];
                if (i == kMeltedSlot) continue;
                const Vec3 x = d.position[i];
                const Vec3 r = (x - anchor) - c;
                for (int a = 0; a < 3; ++a) {
                    const Real side = component(x, a) < component(lo, a)   ? Real(1)
                                      : component(x, a) > component(hi, a) ? Real(-1)
                                                                           : Real(0);
                    if (side == Real(0)) continue;
                    const Vec3 n = axis_vector(a, side);
                    const Real k = Real(1) / M + dot(n, cross(inverse_inertia * cross(r, n), r));
                    const Real before = side * component(wall_impulse[s], a);
                    const Real vn = dot(V + cross(omega, r), n);
                    const Real after = before - vn / k > Real(0) ? before - vn / k : Real(0);
                    V += ((after - before) / M) * n;
                    omega += inverse_inertia * cross(r, (after - before) * n);
                    wall_impulse[s] += axis_vector(a, side * (after - before));
                }
                // Its deepest obstacle contact, the same way along that obstacle's normal.
                Vec3 n{0, 0, 0};
                Real depth = 0;
                if (!p.obstacles.deepest(x, obj.wall_margin, obj.margin, n, depth)) continue;
                const Real k = Real(1) / M + dot(n, cross(inverse_inertia * cross(r, n), r));
                const Real before = obstacle_impulse[s];
                const Real vn = dot(V + cross(omega, r), n);
                const Real after = before - vn / k > Real(0) ? before - vn / k : Real(0);
                V += ((after - before) / M) * n;
                omega += inverse_inertia * cross(r, (after - before) * n);
                obstacle_impulse[s] = after;
            }
        }
        // Friction on the body's sliding, through its centre (it turns nothing), then the body out
        // of every wall.
        Vec3 shift{0, 0, 0};
        for (int f = 0; f < 6; ++f) {
            if (!(depth[f] > Real(0))) continue;
            const Vec3 n = axis_vector(f / 2, (f & 1) ? Real(-1) : Real(1));
            if (obj.friction > Real(0)) V -= obj.friction * (V - dot(V, n) * n);
            shift += depth[f] * n;
        }
        // The obstacles: friction along the deepest contact's normal, and the body out of every
        // contact in sweeps (an IBP needs depth along n, less what the shift so far gives).
        if (p.obstacles.any()) {
            Real deepest = 0;
            Vec3 deepest_normal{0, 0, 0};
            for (int sweep = 0; sweep < kObstacleSweeps; ++sweep) {
                for (std::uint32_t s = object_ibp_begin[o]; s < object_ibp_begin[o + 1]; ++s) {
                    const std::uint32_t i = d.store_of_slot[s];
                    if (i == kMeltedSlot) continue;
                    Vec3 n{0, 0, 0};
                    Real depth = 0;
                    if (!p.obstacles.deepest(d.position[i], obj.wall_margin, obj.margin, n, depth)) continue;
                    if (sweep == 0 && depth > deepest) deepest = depth, deepest_normal = n;
                    const Real need = depth - dot(shift, n);
                    if (need > Real(0)) shift += need * n;
                }
            }
            if (deepest > Real(0) && obj.friction > Real(0))
                V -= obj.friction * (V - dot(V, deepest_normal) * deepest_normal);
        }
        for (std::uint32_t s = object_ibp_begin[o]; s < object_ibp_begin[o + 1]; ++s) {
            const std::uint32_t i = d.store_of_slot[s];
            if (i == kMeltedSlot) continue;
            const Vec3 x = d.position[i];
            d.velocity[i] = V + cross(omega, (x - anchor) - c);
            d.position[i] = x + shift;
        }
    });
}

// Whole-body damping (objects[].lsm.body_damping, rate k): every IBP of an elastic object moves
// its velocity toward the body's rigid motion at its place, V + ω × (x - c), by 1 - e^(-k Δt).
// Per region (lsm.damping) a bending mode is nearly rigid in each region and is not damped; the
// whole body's deformation is. Momentum and angular momentum are kept (Σ m (V + ω × r) = M V,
// Σ m r × (V + ω × r) = I ω = L). A pinned body's rigid motion is none: its velocity decays
// (toward a rigid fit, a swinging beam would keep the swing the fit turns with). One thread per
// object sums its IBPs in slot order (deterministic), then one per IBP.
inline void lsm_body_damping(const DeviceContext& device, const LsmData d, Real dt, const std::uint32_t* object_ibp_begin,
                             std::size_t object_count, BodyMotion* motion) {
    parallel_for(device, "lsm_body_motion", object_count, [=] MW_HD(std::size_t o) {
        const LsmObjectParams obj = d.objects[o];
        if (obj.rigid || !(obj.body_damping_rate > Real(0))) return;
        BodySums body;
        bool anchored = false, pinned = false;
        Vec3 a{0, 0, 0};
        for (std::uint32_t s = object_ibp_begin[o]; s < object_ibp_begin[o + 1]; ++s) {
            const std::uint32_t i = d.store_of_slot[s];
            if (i == kMeltedSlot) continue;
            pinned = pinned || d.pinned[s];
            if (!anchored) a = d.position[i], anchored = true;
            body.add(d.mass[s], d.position[i] - a, d.velocity[i]);
        }
        // A pinned body has no rigid motion to keep: its whole velocity decays.
        BodyMotion m = body.M > Real(0) && !pinned ? body_motion(body) : BodyMotion{};
        m.anchor = a;
        motion[o] = m;
    });
    parallel_for(device, "lsm_body_damping", d.ibp_count, [=] MW_HD(std::size_t si) {
        const std::uint32_t s = static_cast<std::uint32_t>(si);
        const std::uint32_t i = d.store_of_slot[s];
        if (i == kMeltedSlot || d.pinned[s]) return;
        const std::int32_t o = d.object[s];
        const LsmObjectParams obj = d.objects[o];
        if (obj.rigid || !(obj.body_damping_rate > Real(0))) return;
        const BodyMotion m = motion[o];
        const Vec3 rigid = m.velocity + cross(m.spin, (d.position[i] - m.anchor) - m.centre);
        d.velocity[i] += (Real(1) - std::exp(-obj.body_damping_rate * dt)) * (rigid - d.velocity[i]);
    });
}

// Goals without updating anything (tests): goal[s] = x_s + (g_s - x_s).
inline void lsm_goals(const DeviceContext& device, const LsmData d, View<Vec3> goal) {
    parallel_for(device, "lsm_goals", d.ibp_count, [=] MW_HD(std::size_t si) {
        const std::uint32_t s = static_cast<std::uint32_t>(si);
        const std::uint32_t i = d.store_of_slot[s];
        if (i == kMeltedSlot) {
            goal[s] = Vec3{0, 0, 0};
            return;
        }
        const Vec3 x = d.position[i];
        Mat3 mean_rotation;
        Vec3 rigid_offset, external;
        goal[s] = x + lsm_goal_offset(d, s, x, Vec3{0, 0, 0}, mean_rotation, false, rigid_offset, external);
    });
}

MW_BACKEND_END
