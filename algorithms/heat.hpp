// Heat conduction between fluid and moving solids: the first half of melting (docs/method.md,
// "Melting"; docs/heat.md). Every fluid particle and every surface and inner particle of an
// elastic or rigid object carries a temperature T; static walls, static boxes and static objects
// are adiabatic (no heat crosses them) and the mesh vertices (GPs) keep their initial value.
//
// The heat equation C dT/dt = ∇·(k ∇T) with Brookshaw's (1985) SPH Laplacian, which only needs
// W' and gives a weight that is never negative (Cleary & Monaghan's 1999 form for conduction
// between materials), written per particle as
//
//   M_i dT_i/dt = V_i Σ_j c_ij (T_j - T_i),   c_ij = 2 s k_ij V_j F_ij γ_ij,   F_ij = -W'(r_ij) / r_ij.
//
// - C = ρc is the material's heat capacity per volume and k = α C its conductivity (the fluid's,
//   or the particle's object's: the scene gives the diffusivity α and C); k_ij = 2 k_i k_j /
//   (k_i + k_j) the pair's (two half-spacings in series: right at an interface, k for one material).
// - V = m/ρ0 for fluid (an incompressible fluid's volume) and this step's Akinci volume V_b for a
//   solid's particle. M_i = V⁰_i C_i is the particle's heat capacity, fixed for the run: V⁰ is m/ρ0
//   for fluid and a solid particle's V_b as the scene starts (a heat content taken with each
//   step's volumes, m/ρ for the fluid, drifted by 0.3% in a pool settling around a box).
// - γ_ij = (γ_i + γ_j)/2, γ = ρ0/ρ for fluid (its PCISPH density, clamped to [1, 3]) and 1 for a
//   solid's particle, makes up for the neighbours missing at a free surface (without it a fluid
//   bar 9 r0 across conducted 6% slow; with m/ρ as the volumes instead, 6% fast).
// - s makes the sum exact on a regular lattice at spacing r0 (pcisph_delta.hpp, laplacian_moment:
//   at h = 2 r0 the raw sum is 2% fast for the cubic spline).
// The heat Σ_i M_i T_i is conserved, V_i c_ij = V_j c_ji, while every particle's update stays
// within the limit below.
//
// Time: explicit sub-steps, as many as keep g = δt V_i Σ_j c_ij / M_i at most 1 for every particle as
// the scene starts (HeatConduction::calibrate: the solids' overlapping surface and inner
// particles reach 1.6 times a fluid lattice's g), at most `max_substeps`. Then each update is a
// weighted mean of T_i and its neighbours', so no temperature leaves their range. A particle whose
// g exceeds 1 (a neighbourhood packed tighter than at the start, or a step past the cap) moves to
// its neighbours' weighted mean instead of past it: the update stays a mean, stable at any Δt,
// but that particle's exchange is no longer symmetric, so it conserves heat only approximately.
//
// Why not the paper's backward Euler (one pass per step, stable at any Δt): solved by Jacobi sweeps
// of the implicit system, one sweep diffuses at 1/(1 + D) of the true rate (0.56 at a Fourier
// number α Δt / r0² of 0.2, 0.21 at 1), and reaching 5% takes 4 sweeps at 0.2 and 28 at 2 (then
// about 11% slow). Explicit sub-steps are within 1% of the true rate at every Fourier number
// tried, in 1 pass at 0.2 and 9 at 2 (tests/core/test_heat.cpp, docs/heat.md).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>

#include <string>
#include <type_traits>
#include <vector>

#include "algorithms/boundary_volumes.hpp"
#include "algorithms/module.hpp"
#include "algorithms/particle_types.hpp"
#include "algorithms/pcisph_delta.hpp"
#include "algorithms/solid_bodies.hpp"
#include "backend/reduce_ops.hpp"

MW_BACKEND_BEGIN

// A material's thermal properties.
struct HeatMaterial {
    Real diffusivity = 0;  // α, m²/s
    Real capacity = 1;     // C = ρc, J/(m³ K)
};

// Where a particle's material and volumes come from (read once per step, by the first pass).
struct HeatMaterials {
    View<const std::uint8_t> type;          // store fields
    View<const Real> density;               // fluid: this step's ρ, for γ = ρ0/ρ
    View<const Real> boundary_volume;       // solids' particles: V_b (this step's)
    View<const std::int32_t> solid_slot;    // solids' particles: their slot (empty without solids)
    const std::int32_t* slot_object = nullptr;    // slot -> index of its object in the setup's solids
    const HeatMaterial* objects = nullptr;        // per object
    std::size_t solid_slots = 0;                  // IBP and SBP slots (the solids' conducting particles)
    HeatMaterial fluid;
    Real fluid_mass = 0;
    Real rest_density = 0;  // ρ0: the fluid's V⁰ = m/ρ0
    // Melting objects' heat absorbed at the melting point, in kelvins of their heat capacity
    // (melting.hpp): part of the heat content. Empty without a melting object.
    View<const Real> latent;
};

// A pass's two sums for particle i: Σ_j c_ij and Σ_j c_ij T_j (c without δt s).
struct HeatSums {
    Real weight = 0, weighted = 0;
    MW_INLINE HeatSums& operator+=(const HeatSums& o) {
        weight += o.weight;
        weighted += o.weighted;
        return *this;
    }
};

// The neighbours a fluid particle conducts with: fluid and moving solids. The lists hold the
// static boundary too, whose terms are 0 (the walls are adiabatic); the grid skips their cells.
template <class F>
MW_INLINE HeatSums sum_conducting(const GridView& grid, std::size_t i, Vec3 x, F&& f) {
    HeatSums sums = grid.sum_fluid(i, x, f);
    grid.for_each_solid(x, [&](std::uint32_t j) { sums += f(j); });
    return sums;
}
template <class F>
MW_INLINE HeatSums sum_conducting(const NeighborListView& lists, std::size_t i, Vec3 x, F&& f) {
    HeatSums sums = lists.sum_fluid(i, x, f);
    sums += lists.sum_boundary(i, x, f);
    return sums;
}

// A particle's conduction data for a step: its volume V, conductivity k, heat capacity M (J/K)
// and free-surface factor γ.
struct HeatParticle {
    Real volume = 0, conductivity = 0, capacity = 1;
    Real deficiency = 1;  // γ
};

// The pair term of c_ij / (2 s): k_ij V_j F_ij, from i's conductivity and j's data; 0 for a j at
// or past `end` (a static neighbour in the lists), which reads particle 0's data instead.
template <class Kernel>
MW_INLINE Real heat_pair(Vec3 xi, Real k_i, Real gamma_i, std::uint32_t j, std::size_t end, View<const Vec3> position,
                         View<const HeatParticle> particle, Kernel kernel, std::uint32_t& read) {
    const bool conducts = j < end;
    read = conducts ? j : 0u;
    const HeatParticle pj = particle[read];
    const Real f = conducts ? kernel.laplacian_weight_r2(norm2(xi - position[j])) : Real(0);
    const Real k_sum = k_i + pj.conductivity;
    const Real k_pair = k_sum > Real(0) ? Real(2) * k_i * pj.conductivity / k_sum : Real(0);
    return k_pair * pj.volume * f * Real(0.5) * (gamma_i + pj.deficiency);
}

// One explicit sub-step over particles [first, first + count), from `in` to `out` (never the same):
// out_i = T_i + λ (a Σ_j c_ij T_j - g T_i), g = a Σ_j c_ij, a = δt 2 s V_i / M_i, λ = min(1, 1/g),
// with c_ij = k_ij V_j F_ij over the conducting particles [0, end). Otherwise branch-free terms
// (F is 0 out of range and for i itself), as in the PCISPH sums.
template <class Neighbors, class Kernel>
void heat_substep(const DeviceContext& device, const Neighbors& neighbors, std::size_t first, std::size_t count, std::size_t end,
                  View<const Vec3> position, View<const HeatParticle> particle, View<const Real> in, View<Real> out,
                  Real dt_times_scale, Kernel kernel) {
    // The grid offers every particle of the cells around, five in six of them farther than h in
    // 3D: testing the distance first skips their loads (walked on the grid without the test, a
    // solid's particles took twice the fluid's time on OpenMP). The lists hold pairs within h
    // already, whose sums stay branch-free.
    constexpr bool test_range = std::is_same<Neighbors, GridView>::value;
    const Real h2 = kernel.h * kernel.h;
    parallel_for(device, "heat_substep", count, [=] MW_HD(std::size_t k) {
        const std::size_t i = first + k;
        const Vec3 xi = position[i];
        const Real k_i = particle[i].conductivity, gamma_i = particle[i].deficiency;
        const HeatSums sums = sum_conducting(neighbors, i, xi, [&](std::uint32_t j) {
            if (test_range && !(norm2(xi - position[j]) < h2)) return HeatSums{};
            std::uint32_t read = 0;
            const Real c = heat_pair(xi, k_i, gamma_i, j, end, position, particle, kernel, read);
            return HeatSums{c, c * in[read]};
        });
        const Real a_i = dt_times_scale * particle[i].volume / particle[i].capacity;
        const Real g = a_i * sums.weight;
        const Real share = g > Real(1) ? Real(1) / g : Real(1);
        out[i] = in[i] + share * (a_i * sums.weighted - g * in[i]);
    });
}

// The heat content Σ M (T + latent) of particles [0, count), J (T in °C), in double; `latent`
// (melting.hpp) may be empty.
inline double heat_content(const DeviceContext& device, std::size_t count, View<const HeatParticle> particle, View<const Real> temperature,
                           View<const Real> latent) {
    const bool has_latent = latent.data() != nullptr;
    return transform_reduce(device, "heat_content", count, 0.0, SumOp{}, [=] MW_HD(std::size_t i) {
        const double stored = has_latent ? double(latent[i]) : 0.0;
        return double(particle[i].capacity) * (double(temperature[i]) + stored);
    });
}

// The heat conduction module (stage "heat", with heat.enabled): the store's "temperature" field,
// each object's material, and the sub-steps' buffers.
template <class Kernel>
class HeatConduction final : public Module {
   public:
    // Registers the store field `temperature`, filled from the setup in the store's order `order`.
    // Throws InputError for a non-finite temperature or material.
    HeatConduction(SimulationState<Kernel>& state, const SimulationSetup& setup, const std::vector<std::uint32_t>& order,
                   BoundaryVolumes<Kernel>& volumes, const SolidBodies& solids)
        : state_(state), volumes_(volumes), solids_(solids) {
        const SimulationParams& params = state.params;
        if (!params.heat.enabled) return;
        const std::size_t n = order.size(), moving = state.store.moving_count();
        if (setup.temperature.size() != n)
            throw InputError("simulation setup: heat conduction needs a temperature for each of the " +
                             std::to_string(n) + " particles (got " + std::to_string(setup.temperature.size()) + ")");
        std::vector<Real> temperature(n);
        for (std::size_t k = 0; k < n; ++k) {
            temperature[k] = setup.temperature[order[k]];
            if (!std::isfinite(double(temperature[k])))
                throw InputError("simulation setup: particle " + std::to_string(order[k]) +
                                 " has a non-finite temperature");
        }
        if (!(params.heat.fluid_diffusivity >= 0) || !std::isfinite(double(params.heat.fluid_diffusivity)))
            throw InputError("simulation setup: the fluid's thermal diffusivity must be finite and >= 0");
        if (!(params.heat.fluid_capacity > 0) || !std::isfinite(double(params.heat.fluid_capacity)))
            throw InputError("simulation setup: the fluid's heat capacity must be finite and > 0");
        std::vector<HeatMaterial> materials;
        for (const SolidSetup& solid : setup.solids) {
            if (!(solid.thermal_diffusivity >= 0) || !std::isfinite(double(solid.thermal_diffusivity)))
                throw InputError("simulation setup: solid \"" + solid.name +
                                 "\" has a thermal diffusivity that is not finite and >= 0");
            if (!(solid.heat_capacity > 0) || !std::isfinite(double(solid.heat_capacity)))
                throw InputError("simulation setup: solid \"" + solid.name +
                                 "\" has a heat capacity that is not finite and > 0");
            materials.push_back(HeatMaterial{solid.thermal_diffusivity, solid.heat_capacity});
        }
        if (params.heat.max_substeps < 1)
            throw InputError("simulation setup: heat conduction needs max_substeps >= 1");
        temperature_ = &state.store.template add<Real>("temperature", FieldLife::kPersistent);
        temperature_->upload(temperature);
        object_heat_.upload(materials);
        max_substeps_ = params.heat.max_substeps;
        // Brookshaw's Laplacian, rescaled to be exact on the fluid's lattice (pcisph_delta.hpp).
        lattice_scale_ = heat_lattice_scale(prototype_sums(state.fluid.kernel, params.fluid.spacing, Kernel::kDimensions));
        particle_.assign(moving, HeatParticle{});
        other_.assign(moving, Real(0));
        solid_rest_volume_.assign(1, Real(0));  // start() sizes it
        heat_content(state.device, moving, particle_.cview(), other_.cview(), View<const Real>{});  // its reduction workspace
    }

    bool active() const { return temperature_ != nullptr; }
    DeviceArray<Real>* temperature() { return temperature_; }

    void bind(StepPlan& plan) override {
        if (active()) plan.bind("heat", [this](StepContext& step) { conduct(step); });
    }

    // With the scene's first volumes and grid: each solid particle's V0 (its V_b now), and the
    // largest g / dt over particles [0, solid_end) (4.33 alpha / r0^2 in a fluid at rest for the
    // cubic spline at h = 2 r0; the solids' overlapping surface and inner particles reach 1.6
    // times their material's). One neighbour pass and a reduction.
    void start(const StepContext& first) override {
        if (!active()) return;
        latent_ = state_.store.template find<Real>("latent_heat");  // melting.hpp's, when an object melts
        if (solids_.active()) volumes_.update_moving(first.neighbors.grid, first.ranges);
        const HeatMaterials m = materials();
        const std::size_t fluid_end = first.ranges.fluid_end, solid_end = first.ranges.solid_end;
        solid_rest_volume_.assign(std::max<std::size_t>(1, m.solid_slots), Real(0));
        if (solid_end == 0) return;
        const View<Real> rest = solid_rest_volume_.view();
        if (solid_end > fluid_end)
            parallel_for(state_.device, "heat_solid_rest_volume", solid_end - fluid_end, [=] MW_HD(std::size_t k) {
                const std::size_t i = fluid_end + k;
                rest[static_cast<std::size_t>(m.solid_slot[i])] = m.boundary_volume[i];
            });
        describe_particles(solid_end, m, View<const Real>{});
        const View<const HeatParticle> particle = particle_.cview();
        const View<const Vec3> position = state_.store.position.cview();
        const GridView grid = first.neighbors.grid;
        const Kernel kernel = state_.fluid.kernel;
        const Real two_s = static_cast<Real>(2 * lattice_scale_);
        const Real largest =
            transform_reduce(state_.device, "heat_calibrate", solid_end, Real(0), MaxOp{}, [=] MW_HD(std::size_t i) {
                const Vec3 xi = position[i];
                const Real k_i = particle[i].conductivity, gamma_i = particle[i].deficiency;
                const HeatSums sums = sum_conducting(grid, i, xi, [&](std::uint32_t j) {
                    std::uint32_t read = 0;
                    return HeatSums{heat_pair(xi, k_i, gamma_i, j, solid_end, position, particle, kernel, read), Real(0)};
                });
                return two_s * particle[i].volume / particle[i].capacity * sums.weight;
            });
        d_per_dt_ = double(largest);
    }

    // Advances the temperatures by the step over the fluid [0, fluid_end), whose rows come from the
    // step's neighbourhood, and the moving solids' particles [fluid_end, solid_end) (the grid). The
    // sub-steps alternate between the store's field and other_, starting where an odd or even count
    // ends in the store. Then the heat content (a reduction read back: the run's conservation check,
    // stats.csv). Here, where the step's length is settled (PCISPH may have halved it) and nothing
    // has moved yet.
    void conduct(StepContext& step) {
        // Without fluid the solids' volumes are the heat's own to compute.
        if (solids_.active() && !volumes_.updated_every_step()) volumes_.update_moving(step.neighbors.grid, step.ranges);
        const HeatMaterials m = materials();
        const std::size_t fluid_end = step.ranges.fluid_end, solid_end = step.ranges.solid_end;
        const int substeps = substeps_for(double(step.dt));
        last_substeps_ = substeps;
        if (solid_end == 0) return;
        View<Real> temperature = temperature_->view();
        describe_particles(solid_end, m, substeps % 2 == 1 ? View<const Real>(temperature) : View<const Real>{});
        const Real a = static_cast<Real>(2 * lattice_scale_ * double(step.dt) / substeps);
        // An odd count starts from the copy in other_, an even one from the store: the last lands there.
        View<Real> in = substeps % 2 == 1 ? other_.view() : temperature;
        View<Real> out = substeps % 2 == 1 ? temperature : other_.view();
        const View<const Vec3> position = state_.store.position.cview();
        for (int substep = 0; substep < substeps; ++substep) {
            if (fluid_end > 0)
                step.neighbors.visit([&](const auto& rows) {
                    heat_substep(state_.device, rows, 0, fluid_end, solid_end, position, particle_.cview(), in, out,
                                 a, state_.fluid.kernel);
                });
            if (solid_end > fluid_end)
                heat_substep(state_.device, step.neighbors.grid, fluid_end, solid_end - fluid_end, solid_end, position,
                             particle_.cview(), in, out, a, state_.fluid.kernel);
            std::swap(in, out);
        }
        last_content_ = heat_content(state_.device, solid_end, particle_.cview(), temperature, m.latent);
    }

    // The sub-steps a step of dt needs (g <= 1 each), and takes (at most max_substeps).
    int substeps_needed(double dt) const {
        const double n = std::ceil(d_per_dt_ * dt);
        return n < 1 ? 1 : n > 1e9 ? 1000000000 : static_cast<int>(n);
    }
    int substeps_for(double dt) const { return std::min(substeps_needed(dt), max_substeps_); }

    void report_columns(std::vector<std::string>& names) const override {
        if (!active()) return;
        names.push_back("heat_substeps");
        names.push_back("heat_content");
    }
    // The heat content is in J with T in degrees C (any consistent unit).
    void report(std::vector<double>& values) const override {
        if (!active()) return;
        values.push_back(last_substeps_);
        values.push_back(last_content_);
    }
    void check(const StateArchive& in) const override {
        if (active() && !in.has("store.temperature"))
            throw InputError("checkpoint: it holds no temperatures, and this scene conducts heat (heat.enabled); it "
                             "was written for another scene");
    }
    std::size_t bytes() const override {
        return particle_.bytes() + other_.bytes() + solid_rest_volume_.bytes() + object_heat_.bytes();
    }

    // Each conducting particle's volume, conductivity, heat capacity and gamma for this step, and a
    // copy of `temperature` (when given: an odd count of sub-steps starts from it) in other_.
    // Public only because nvcc allows no device lambda in a private member function.
    void describe_particles(std::size_t solid_end, const HeatMaterials& m, View<const Real> temperature) {
        const View<Real> other = other_.view();
        const View<HeatParticle> particle = particle_.view();
        const View<const Real> rest = solid_rest_volume_.cview();
        const bool copy = temperature.data() != nullptr;
        parallel_for(state_.device, "heat_materials", solid_end, [=] MW_HD(std::size_t i) {
            if (copy) other[i] = temperature[i];
            const bool fluid = m.type[i] == kFluid;
            const std::int32_t slot = fluid ? 0 : m.solid_slot[i];
            const HeatMaterial material = fluid ? m.fluid : m.objects[m.slot_object[slot]];
            HeatParticle p;
            const Real rest_volume = fluid ? m.fluid_mass / m.rest_density : rest[static_cast<std::size_t>(slot)];
            p.volume = fluid ? rest_volume : m.boundary_volume[i];
            const Real gamma = fluid ? m.rest_density / m.density[i] : Real(1);
            p.deficiency = gamma < Real(1) ? Real(1) : gamma > Real(3) ? Real(3) : gamma;
            p.capacity = rest_volume * material.capacity;
            p.conductivity = material.diffusivity * material.capacity;
            particle[i] = p;
        });
    }

   private:
    // Where the stage finds each particle's material and volume.
    HeatMaterials materials() const {
        const ParticleStore& store = state_.store;
        HeatMaterials m;
        m.type = store.type.cview();
        m.density = store.density.cview();
        m.boundary_volume = volumes_.volumes();
        m.fluid = HeatMaterial{state_.params.heat.fluid_diffusivity, state_.params.heat.fluid_capacity};
        m.fluid_mass = state_.fluid.mass;
        m.rest_density = state_.fluid.rest_density;
        m.latent = latent_ ? latent_->cview() : View<const Real>{};
        if (solids_.active()) {
            m.solid_slot = solids_.solid_slot_view();
            m.slot_object = solids_.slot_objects().data();
            m.objects = object_heat_.view().data();
            m.solid_slots = solids_.boundary_slot_count();
        }
        return m;
    }

    SimulationState<Kernel>& state_;
    BoundaryVolumes<Kernel>& volumes_;
    const SolidBodies& solids_;
    DeviceArray<Real>* temperature_ = nullptr;  // store field, degrees C
    DeviceArray<Real>* latent_ = nullptr;       // store field of the melting module, when an object melts
    int max_substeps_ = 1;
    double lattice_scale_ = 1;
    double d_per_dt_ = 0;  // the largest g / dt
    int last_substeps_ = 0;
    double last_content_ = 0;
    DeviceArray<HeatParticle> particle_;   // per moving particle, this step's
    DeviceArray<Real> other_;              // the sub-steps' second buffer
    DeviceArray<Real> solid_rest_volume_;  // per solid slot (IBPs, SBPs), its V0
    DeviceArray<HeatMaterial> object_heat_;  // per object of the setup, its thermal properties
};

MW_BACKEND_END
