// PCISPH (Solenthaler & Pajarola 2009) with Akinci boundary particles, as in docs/method.md, written
// once against the backend abstraction. Every stage is a gather: particle i reads its neighbours
// and writes only itself, so results do not depend on thread scheduling.
//
// Pressure force: the symmetric form -m Σ_j (p_i/ρ_i² + p_j/ρ_j²) ∇W_ij, which is the form PCISPH's
// δ is derived for. (The paper's Eq. 3 as printed, (p_i + p_j)/(2 ρ_i ρ_j), is half of it near ρ0
// and would make δ twice too soft.) Boundary particles mirror the fluid pressure (Akinci 2012):
// -ψ_b (p_i/ρ_i²) ∇W_ib with ψ_b = ρ0 V_b.
#pragma once
#include "algorithms/lsm_regions.hpp"
#include "algorithms/neighbor_grid.hpp"
#include "algorithms/sph_kernels.hpp"
#include "algorithms/virtual_boundary.hpp"
#include "algorithms/wall_contact.hpp"
#include "algorithms/wall_mirror.hpp"

MW_BACKEND_BEGIN

// One per kernel (sph_kernels.hpp): the solver's functions below are templates over it.
template <class Kernel>
struct FluidConstants {
    Kernel kernel;
    Real rest_density = 0;    // ρ0
    Real mass = 0;            // fluid particle mass
    Real viscosity = 0;       // μ
    Real wall_viscosity = 0;  // μ of the fluid–wall friction (Eq. 8 against boundary particles)
    Vec3 gravity{0, 0, 0};
    WallMirrors mirrors;      // the domain's free-slip walls, for Eq. 4 next to them
};

// How a step's PCISPH iterations ended: below the tolerance; diverged (the error rose to twice the
// lowest it reached, fluid.hpp); or out of iterations above the tolerance.
enum class PcisphOutcome { kConverged, kDiverged, kOutOfIterations };

struct DensityError {
    double sum = 0;   // Σ max(ρ - ρ0, 0) / ρ0
    Real max = 0;
};
struct DensityErrorOp {
    MW_INLINE DensityError operator()(const DensityError& a, const DensityError& b) const {
        return DensityError{a.sum + b.sum, a.max < b.max ? b.max : a.max};
    }
};

// Non-pressure acceleration of fluid: gravity, viscosity (the paper's Eq. 4 with the Müller
// viscosity Laplacian, which is never negative) and friction against boundary particles (Eq. 8,
// ψ_b = ρ0 V_b, ρ_b = ρ0: a_i += μ_w V_b/ρ0 (v_b - v_i) ∇²W). Densities are the previous step's.
// Next to the domain's free-slip walls, Eq. 4 also sums over the fluid's mirror images beyond
// them (wall_mirror.hpp), so the layer h thick along a wall keeps its full viscous stress. Each
// pair (i, j) then also meets through the images, with the same weight both ways
// (|x_i - x_j'| = |x_j - x_i'|), and adds -μ V_i V_j ∇²W |v_i - v_j'|² to the power: never
// positive, like the fluid pairs.
// Written against the gather interface (grid or lists); every term is 0 by itself for a pair out
// of range and for i itself (v_i - v_i), so no test is needed. (i's own image is not 0: it brakes
// i's velocity into the wall, which the fluid pairs cannot see when all move alike.)
template <class Neighbors, class Kernel>
void compute_viscosity_acceleration(const DeviceContext& device, Neighbors neighbors, std::size_t fluid_count, View<const Vec3> position,
                                    View<const Vec3> velocity, View<const Real> density,
                                    View<const Real> boundary_volume, View<Vec3> acceleration,
                                    FluidConstants<Kernel> c) {
    const bool friction = c.wall_viscosity > Real(0);
    const Real h2 = c.kernel.h * c.kernel.h;
    parallel_for(device, "viscosity", fluid_count, [=] MW_HD(std::size_t i) {
        const Vec3 xi = position[i], vi = velocity[i];
        Vec3 fluid_sum = neighbors.sum_fluid(i, xi, [&](std::uint32_t j) {
            return (c.kernel.laplacian_visc_r2(norm2(xi - position[j])) / density[j]) * (velocity[j] - vi);
        });
        c.mirrors.for_each_reflection(xi, [&](Vec3 scale, Vec3 offset) {
            fluid_sum += neighbors.sum_fluid(i, xi, [&](std::uint32_t j) {
                // Only images of neighbours within h: the grid offers more candidates than the
                // lists, and a particle that strayed past a face could otherwise meet an image
                // that its partner does not enumerate (wall_mirror.hpp).
                const Real neighbour = norm2(xi - position[j]) < h2 ? Real(1) : Real(0);
                const Vec3 image = offset + hadamard(scale, position[j]);
                return (neighbour * c.kernel.laplacian_visc_r2(norm2(xi - image)) / density[j]) *
                       (hadamard(scale, velocity[j]) - vi);
            });
        });
        Vec3 a = c.gravity + (c.viscosity * c.mass / density[i]) * fluid_sum;
        if (friction)
            a += (c.wall_viscosity / c.rest_density) * neighbors.sum_boundary(i, xi, [&](std::uint32_t b) {
                return (boundary_volume[b] * c.kernel.laplacian_visc_r2(norm2(xi - position[b]))) * (velocity[b] - vi);
            });
        acceleration[i] = a;
    });
}

// x*_i = x_i + Δt v*_i with v*_i = v_i + Δt (a_np + a_p), then the position rule of the
// velocity–position correction: against moving solids' SBPs where it is on (virtual_boundary.hpp),
// then against the walls (wall_contact.hpp). Without a non-pressure field, a_np is gravity.
// A null pressure_acc means no pressure acceleration yet.
inline void predict_positions(const DeviceContext& device, std::size_t fluid_count, View<const Vec3> position, View<const Vec3> velocity,
                              const Vec3* nonpressure, const Vec3* pressure_acc, View<Vec3> predicted, Vec3 gravity,
                              Real dt, WallContact walls, SolidSurface solids = SolidSurface{}) {
    parallel_for(device, "pcisph_predict", fluid_count, [=] MW_HD(std::size_t i) {
        Vec3 a = nonpressure ? nonpressure[i] : gravity;
        if (pressure_acc) a += pressure_acc[i];
        const Vec3 v = velocity[i] + dt * a;
        Vec3 x = position[i] + dt * v;
        if (solids.active())
            x = solids.correct_predicted(static_cast<std::uint32_t>(i), x, position[i], velocity[i], position, velocity);
        predicted[i] = walls.correct_predicted(x, v);
    });
}

// A rigid or solid elastic object's expected acceleration in the step: linear, and angular about
// its centre (coupling.hpp, relax_object_accelerations).
struct ObjectResponse {
    Vec3 linear{0, 0, 0}, angular{0, 0, 0}, centre{0, 0, 0};
};

// Where PCISPH meets the moving solids' boundary particles (store indices below `end`, above the
// fluid) under coupling.predict_solids: where they will be at the end of the step, not where they
// start it. LSM moves a solid after PCISPH, so a solid entering the fluid at the CFL step (0.4 r0
// a step) would otherwise land inside fluid that was solved against where it had been: a box
// thrown flat onto a resting pool at 2.5 m/s left a fluid particle 0.59 r0 under its surface
// particles, and PCISPH diverged at every halving of the next step. A rigid object's particle is
// taken Δt ahead at its own velocity (rotation included), changed within the step by the
// accelerations the solve expects (coupling.strong); a soft object's at its object's mean
// velocity, since its own carries the object's vibration, which the fluid's pressure would answer
// (the floating jelly's pool ran three times as fast; docs/coupling.md, "Solids met where they
// will be"), changed likewise for a solid elastic one (not a melting one). A cloth's particles are
// taken ahead each at its own velocity, changed by the acceleration the solve expects of it
// (coupling.strong). Static boundary particles stay put.
struct SolidLookahead {
    const Vec3* velocity = nullptr;            // the store's; null: every boundary particle where it is
    const Vec3* object_velocity = nullptr;        // per object, its mean velocity
    const LsmObjectParams* objects = nullptr;     // per object: rigid, nodal, answering as one body
    const std::int32_t* solid_slot = nullptr;     // the store's solid_slot field (solid_bodies.hpp)
    const std::int32_t* slot_object = nullptr;    // per IBP and SBP slot, its object
    // Per object, the accelerations the solve expects the step to give an object answering as one
    // body (gravity and the fluid's pressure, coupling.strong; coupling.hpp); null: none, it keeps
    // its velocity.
    const ObjectResponse* object_response = nullptr;
    // Per IBP and SBP slot, the acceleration the solve expects the step to give a cloth's particle
    // (coupling.strong; coupling.hpp, relax_node_accelerations); null: none, it keeps its velocity.
    const Vec3* slot_acceleration = nullptr;
    std::size_t begin = 0, end = 0;            // the moving solids' boundary particles: [begin, end)
    Real dt = 0;
    // Where this iteration meets each of them, by b - begin (place_moving_solids), so that the
    // fluid's sums read one position per pair instead of placing the particle again for every
    // fluid neighbour; null: placed per pair.
    const Vec3* met = nullptr;
    MW_INLINE Vec3 place(std::uint32_t b, Vec3 xb) const {
        if (!velocity || b >= end) return xb;
        const std::int32_t slot = solid_slot[b];
        const std::int32_t o = slot_object[slot];
        if (objects[o].nodal) {
            // A cloth's particles move apart (its sag is no vibration about a mean): each at its own velocity.
            Vec3 v = velocity[b];
            if (slot_acceleration) v += dt * slot_acceleration[slot];
            return xb + dt * v;
        }
        // A rigid object's particle at its own velocity, a soft object's at the object's mean.
        Vec3 v = objects[o].rigid ? velocity[b] : object_velocity[o];
        if (object_response && objects[o].body_answer) {
            const ObjectResponse r = object_response[o];
            v += dt * (r.linear + cross(r.angular, xb - r.centre));
        }
        return xb + dt * v;
    }
    // Boundary particle b where the fluid's sums meet it: the iteration's placement, or where it is.
    MW_INLINE Vec3 met_position(std::uint32_t b, View<const Vec3> position) const {
        if (met && b >= begin && b < end) return met[b - begin];
        return place(b, position[b]);
    }
};

// Each moving solid's boundary particle where this iteration meets it (SolidLookahead::met).
inline void place_moving_solids(const DeviceContext& device, SolidLookahead lookahead, View<const Vec3> position, Vec3* met) {
    const std::size_t begin = lookahead.begin;
    parallel_for(device, "pcisph_place_solids", lookahead.end - begin, [=] MW_HD(std::size_t k) {
        const auto b = static_cast<std::uint32_t>(begin + k);
        met[k] = lookahead.place(b, position[b]);
    });
}

// Predicted density from fluid (at predicted positions) and boundary particles, then
// p_i += δ (ρ*_i - ρ0), clamped at 0 (free-surface particle deficiency), and p_i/ρ_i².
// The first iteration of a step starts from p = 0 (so no separate pass clears the pressure).
// Moving solids' boundary particles are met where `lookahead` puts them, static ones where they are.
template <class Neighbors, class Kernel>
void predict_density_and_pressure(const DeviceContext& device, Neighbors neighbors, std::size_t fluid_count, View<const Vec3> predicted,
                                  View<const Vec3> position, SolidLookahead lookahead,
                                  View<const Real> boundary_volume, View<Real> density, View<Real> pressure,
                                  View<Real> pressure_term, FluidConstants<Kernel> c, Real delta,
                                  bool first_iteration) {
    parallel_for(device, "pcisph_density", fluid_count, [=] MW_HD(std::size_t i) {
        const Vec3 xi = predicted[i];
        const Real fluid_sum = neighbors.sum_fluid(i, position[i], [&](std::uint32_t j) {
            return c.kernel.W_r2(norm2(xi - predicted[j]));
        });
        const Real boundary_sum = neighbors.sum_boundary(i, position[i], [&](std::uint32_t b) {
            return boundary_volume[b] * c.kernel.W_r2(norm2(xi - lookahead.met_position(b, position)));
        });
        const Real rho = c.mass * fluid_sum + c.rest_density * boundary_sum;
        density[i] = rho;
        const Real p_raw = (first_iteration ? Real(0) : pressure[i]) + delta * (rho - c.rest_density);
        const Real p = p_raw > Real(0) ? p_raw : Real(0);
        pressure[i] = p;
        pressure_term[i] = p / (rho * rho);  // p/ρ², read by every neighbour's pressure force
    });
}

inline DensityError density_error(const DeviceContext& device, std::size_t fluid_count, View<const Real> density, Real rest_density) {
    const Real inv_rest = Real(1) / rest_density;
    return transform_reduce(device, "pcisph_density_error", fluid_count, DensityError{}, DensityErrorOp{},
                            [=] MW_HD(std::size_t i) {
                                const Real e = (density[i] - rest_density) * inv_rest;
                                const Real compression = e > Real(0) ? e : Real(0);
                                return DensityError{double(compression), compression};
                            });
}

// a_p,i = -m Σ_j (p_i/ρ_i² + p_j/ρ_j²) ∇W(x*_ij) - Σ_b ψ_b (p_i/ρ_i²) ∇W(x*_i - x_b).
template <class Neighbors, class Kernel>
void pressure_acceleration(const DeviceContext& device, Neighbors neighbors, std::size_t fluid_count, View<const Vec3> predicted,
                           View<const Vec3> position, SolidLookahead lookahead, View<const Real> boundary_volume,
                           View<const Real> pressure_term, View<Vec3> pressure_acc, FluidConstants<Kernel> c) {
    parallel_for(device, "pcisph_pressure_force", fluid_count, [=] MW_HD(std::size_t i) {
        const Vec3 xi = predicted[i];
        const Real pi_rho2 = pressure_term[i];
        // Out-of-range pairs and i itself contribute a zero gradient, so no test is needed.
        const Vec3 fluid_sum = neighbors.sum_fluid(i, position[i], [&](std::uint32_t j) {
            const Vec3 d = xi - predicted[j];
            return (pi_rho2 + pressure_term[j]) * c.kernel.grad_W_r2(d, norm2(d));
        });
        const Vec3 boundary_sum = neighbors.sum_boundary(i, position[i], [&](std::uint32_t b) {
            const Vec3 d = xi - lookahead.met_position(b, position);
            return boundary_volume[b] * c.kernel.grad_W_r2(d, norm2(d));
        });
        pressure_acc[i] = -(c.mass * fluid_sum + (c.rest_density * pi_rho2) * boundary_sum);
    });
}

// Symplectic Euler: v += Δt (a_np + a_p); x += Δt v; then the velocity–position correction
// against the domain walls, the static boxes and static objects (wall_contact.hpp).
// One particle's step: x and v at the step's start in, at its end out (the pressure sensors
// repeat it to read what the walls' correction takes; pressure_sensors.hpp).
MW_INLINE void integrate_particle(Vec3& x, Vec3& v, Vec3 acceleration, Real dt, const WallContact& walls) {
    v = v + dt * acceleration;
    x = x + dt * v;
    walls.correct(x, v);
}

inline void integrate_fluid(const DeviceContext& device, std::size_t fluid_count, View<Vec3> position, View<Vec3> velocity, const Vec3* nonpressure,
                            View<const Vec3> pressure_acc, Vec3 gravity, Real dt, WallContact walls) {
    parallel_for(device, "integrate_fluid", fluid_count, [=] MW_HD(std::size_t i) {
        Vec3 x = position[i], v = velocity[i];
        integrate_particle(x, v, (nonpressure ? nonpressure[i] : gravity) + pressure_acc[i], dt, walls);
        velocity[i] = v;
        position[i] = x;
    });
}

// Kinetic energy, largest speed and the first non-finite particle, in one pass.
struct MotionSummary {
    double kinetic_energy = 0;
    Real max_speed2 = 0;
    std::uint32_t first_bad = 0xffffffffu;
};
struct MotionSummaryOp {
    MW_INLINE MotionSummary operator()(const MotionSummary& a, const MotionSummary& b) const {
        return MotionSummary{a.kinetic_energy + b.kinetic_energy, a.max_speed2 < b.max_speed2 ? b.max_speed2 : a.max_speed2,
                             a.first_bad < b.first_bad ? a.first_bad : b.first_bad};
    }
};
// One particle's share; `index` is reported when it is not finite. |v|² overflowing (speeds past
// ~1e19 m/s in float) counts as not finite: it would make the energy and the CFL step inf.
MW_INLINE MotionSummary particle_motion(Vec3 x, Vec3 v, Real mass, std::uint32_t index) {
    const Real v2 = norm2(v);
    const bool finite = is_finite(v) && is_finite(x) && std::isfinite(v2);
    return MotionSummary{finite ? 0.5 * double(mass) * double(v2) : 0.0, finite ? v2 : Real(0),
                         finite ? 0xffffffffu : index};
}
inline MotionSummary summarize_motion(const DeviceContext& device, std::size_t count, View<const Vec3> position, View<const Vec3> velocity, Real mass) {
    return transform_reduce(device, "motion_summary", count, MotionSummary{}, MotionSummaryOp{}, [=] MW_HD(std::size_t i) {
        return particle_motion(position[i], velocity[i], mass, static_cast<std::uint32_t>(i));
    });
}

MW_BACKEND_END
