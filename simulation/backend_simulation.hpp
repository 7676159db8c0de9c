// One simulation on one backend: its device context, the particle store, the modules of physics
// the scene needs (algorithms/), and the plan their stages make (algorithms/step_plan.hpp).
// step() runs the plan, each stage timed; what a module does, it does in its own file.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "algorithms/boundary_volumes.hpp"
#include "algorithms/emitter.hpp"
#include "algorithms/fluid.hpp"
#include "algorithms/heat.hpp"
#include "algorithms/interface_tension.hpp"
#include "algorithms/melting.hpp"
#include "algorithms/module.hpp"
#include "algorithms/neighbor_search.hpp"
#include "algorithms/pcisph_delta.hpp"
#include "algorithms/pressure_sensors.hpp"
#include "algorithms/solid_bodies.hpp"
#include "algorithms/solid_correction.hpp"
#include "algorithms/statistics.hpp"
#include "algorithms/step_size.hpp"
#include "algorithms/surface_field.hpp"
#include "algorithms/two_way_coupling.hpp"
#include "algorithms/wall_contact.hpp"
#include "algorithms/wall_correction.hpp"
#include "simulation/simulation.hpp"

MW_BACKEND_BEGIN

// One class per smoothing kernel (sph_kernels.hpp); make_simulation() picks the scene's.
template <class Kernel>
class BackendSimulation final : public Simulation {
   public:
    // `threads`: the OpenMP backend's width (0: OpenMP's default); the CUDA backend ignores it.
    BackendSimulation(const SimulationSetup& setup, int threads);

    void step() override {
        device_.activate();
        StepContext step;
        step.time = time_;
        step.dt = step_size_.next(params_, last_max_speed_);
        for (std::size_t s = 0; s < plan_.size(); ++s) {
            timers_.start(int(s));
            plan_.run(s, step);
            timers_.stop(int(s));
        }
        time_ += step.dt;
        ++step_;
        if (step.fluid_motion.first_bad != 0xffffffffu) report_non_finite(step.fluid_motion.first_bad);
        if (step.solid_motion.first_bad != 0xffffffffu)
            report_non_finite(solids_->store_index_of_slot(step.solid_motion.first_bad), "solid inner particle (IBP)");
        fill_report(step);
        // The next CFL step bounds every moving particle's travel, a solid's as well as the fluid's:
        // a solid crossing resting fluid must not jump more than cfl r0 into it. (Its IBPs' speed
        // stands for its SBPs' and GPs', which are interpolated from them.) An emitter's new layers,
        // released at its speed, count too.
        last_max_speed_ = std::max(report_.max_speed, report_.solid_max_speed);
        for (const auto& m : modules_) last_max_speed_ = std::max(last_max_speed_, m->speed_to_come(time_));
    }

    const StepReport& last_report() const override { return report_; }
    std::vector<std::string> stage_names() const override {
        std::vector<std::string> names;
        for (std::size_t s = 0; s < plan_.size(); ++s) names.push_back(plan_.name(s));
        return names;
    }
    void download(HostParticles& out) const override;
    void fluid_color_field(const SurfaceNodes& nodes, std::vector<Real>& color, double& iso) override {
        device_.activate();
        surface_->compute(nodes, color, iso);
    }
    ParticleCounts counts() const override { return state_.counts; }
    // Everything this simulation holds on the device: the store, every module's arrays, and the
    // context's scratch (the sort's buffers, the reductions' partials or CUB's workspace).
    std::size_t device_bytes() const override {
        std::size_t total = state_.store.bytes() + device_.scratch_bytes();
        for (const auto& m : modules_) total += m->bytes();
        return total;
    }
    double time() const override { return time_; }
    int heat_substeps_needed(double dt) const override { return heat_->active() ? heat_->substeps_needed(dt) : 0; }
    std::string backend_name() const override { return kBackendName; }
    std::string device_name() const override { return device_.description(); }
    std::vector<std::array<double, 3>> fluid_force_on_solids() const override { return solids_->object_forces(); }
    std::vector<std::array<double, 3>> pending_contact_impulse() const override {
        return solids_->object_contact_impulses();
    }
    void save_state(StateArchive& out) const override;
    void load_state(const StateArchive& in) override;

   private:
    // The setup's particles into the store: moving particles first, the static boundary last
    // (stable, so ids keep the scene's order). Returns the scene index of each store entry, and
    // widens [lo, hi] to hold every static particle.
    std::vector<std::uint32_t> load_particles(const SimulationSetup& setup, Vec3& lo, Vec3& hi);
    // The fluid's constants from the parameters: the kernel, the particle mass that gives the
    // prototype lattice the rest density, PCISPH's delta, the walls' mirrors.
    void set_fluid_constants();
    // Every module, in the order their stages bind within a stage and their set-up runs.
    void build_modules(const SimulationSetup& setup, const std::vector<std::uint32_t>& order, Vec3 lo, Vec3 hi);
    template <class M, class... Args>
    M& add(Args&&... args) {
        auto module = std::make_unique<M>(std::forward<Args>(args)...);
        M& made = *module;
        modules_.push_back(std::move(module));
        return made;
    }
    void fill_report(const StepContext& step);
    void report_non_finite(std::uint32_t index, const char* what = "fluid particle") const;

    DeviceContext device_;
    SimulationParams params_;
    SimulationState<Kernel> state_{device_, params_};
    std::vector<std::unique_ptr<Module>> modules_;
    // The modules the simulation itself calls, besides their stages.
    NeighborSearch<Kernel>* search_ = nullptr;
    SolidBodies* solids_ = nullptr;
    HeatConduction<Kernel>* heat_ = nullptr;
    SurfaceField<Kernel>* surface_ = nullptr;
    StepPlan plan_;
    StageTimers timers_{device_, int(kStageCount)};
    StepSizeControl step_size_;  // CFL mode: the bound, and the limit PCISPH's retries set
    double time_ = 0;
    long step_ = 0;
    double last_max_speed_ = 0;
    StepReport report_;
};

template <class Kernel>
BackendSimulation<Kernel>::BackendSimulation(const SimulationSetup& setup, int threads)
    : device_(threads), params_(setup.params) {
    const FluidParams& fp = params_.fluid;
    if (!(fp.spacing > 0) || !(fp.support_radius > fp.spacing) || !(fp.rest_density > 0))
        throw InputError("simulation setup: need spacing > 0, support_radius > spacing, rest_density > 0");
    if (params_.dimensions != Kernel::kDimensions)
        throw InputError("simulation setup: a " + std::to_string(params_.dimensions) + "D scene given a " +
                         std::to_string(Kernel::kDimensions) + "D kernel");
    Vec3 lo = params_.domain_min, hi = params_.domain_max;
    const std::vector<std::uint32_t> order = load_particles(setup, lo, hi);
    set_fluid_constants();
    // A scene whose objects melt, or with an emitter, gains fluid: its fluid stages run from the start.
    state_.has_fluid = setup.has_fluid();
    build_modules(setup, order, lo, hi);
    for (const auto& m : modules_) m->bind(plan_);
    plan_.finish();

    // The first sort, so that every per-step buffer (sort keys, lists) is allocated before the
    // first step and device_bytes() is the steady-state figure `info` reports; then each module's
    // own set-up over the scene as it starts.
    StepContext first;
    first.ranges = search_->sort();
    first.neighbors = search_->build_lists(first.ranges);
    for (const auto& m : modules_) m->start(first);
    report_.column_names.clear();
    for (const auto& m : modules_) m->report_columns(report_.column_names);

    // The first CFL step uses the initial speeds, and the emitters'.
    double max_speed2 = 0;
    for (std::size_t i = 0; i < setup.velocity.size(); ++i)
        if (setup.type[i] != kStaticBoundary) max_speed2 = std::max(max_speed2, double(norm2(setup.velocity[i])));
    last_max_speed_ = std::sqrt(max_speed2);
    for (const auto& m : modules_) last_max_speed_ = std::max(last_max_speed_, m->speed_to_come(0));
}

template <class Kernel>
std::vector<std::uint32_t> BackendSimulation<Kernel>::load_particles(const SimulationSetup& setup, Vec3& lo, Vec3& hi) {
    const std::size_t n = setup.position.size();
    if (setup.velocity.size() != n || setup.type.size() != n || setup.object.size() != n)
        throw InputError("simulation setup: position, velocity, type and object lists differ in length");
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_partition(order.begin(), order.end(),
                          [&](std::uint32_t i) { return setup.type[i] != kStaticBoundary; });
    std::size_t moving = 0;
    std::vector<Vec3> position(n), velocity(n);
    std::vector<std::uint8_t> type(n);
    std::vector<std::int32_t> object(n);
    for (std::size_t k = 0; k < n; ++k) {
        const std::uint32_t i = order[k];
        position[k] = setup.position[i];
        velocity[k] = setup.velocity[i];
        type[k] = setup.type[i];
        object[k] = setup.object[i];
        if (type[k] >= kParticleTypeCount)
            throw InputError("simulation setup: unknown particle type " + std::to_string(type[k]));
        if (type[k] != kStaticBoundary) ++moving;
        ++state_.counts.by_type[type[k]];
        if (!is_finite(position[k]) || !is_finite(velocity[k]))
            throw InputError("simulation setup: particle " + std::to_string(i) +
                             " has a non-finite position or velocity");
        if (type[k] == kStaticBoundary) {  // the grid must hold every static particle
            lo = Vec3{std::min(lo.x, position[k].x), std::min(lo.y, position[k].y), std::min(lo.z, position[k].z)};
            hi = Vec3{std::max(hi.x, position[k].x), std::max(hi.y, position[k].y), std::max(hi.z, position[k].z)};
        }
    }
    ParticleStore& store = state_.store;
    store.resize(n, moving);
    store.id.upload(order);
    store.position.upload(position);
    store.velocity.upload(velocity);
    store.type.upload(type);
    store.object.upload(object);
    store.density.fill(params_.fluid.rest_density);
    store.pressure.fill(Real(0));
    return order;
}

template <class Kernel>
void BackendSimulation<Kernel>::set_fluid_constants() {
    const FluidParams& fp = params_.fluid;
    FluidConstants<Kernel>& fluid = state_.fluid;
    fluid.kernel = Kernel::with_support(fp.support_radius);
    fluid.rest_density = fp.rest_density;
    fluid.viscosity = fp.viscosity;
    fluid.wall_viscosity = fp.wall_viscosity;
    fluid.gravity = params_.gravity;
    if (params_.boundary.walls && fp.viscosity > 0)
        fluid.mirrors = WallMirrors{params_.domain_min, params_.domain_max, WallMirrors::faces_in(Kernel::kDimensions),
                                    fp.support_radius};
    // Mass such that the prototype lattice at spacing r0 has exactly the rest density.
    const PrototypeSums sums = prototype_sums(fluid.kernel, fp.spacing, Kernel::kDimensions);
    fluid.mass = static_cast<Real>(fp.rest_density / sums.sum_W);
    state_.delta_times_dt2 = pcisph_delta(sums, fp.rest_density, fluid.mass, 1.0);
}

template <class Kernel>
void BackendSimulation<Kernel>::build_modules(const SimulationSetup& setup, const std::vector<std::uint32_t>& order,
                                              Vec3 lo, Vec3 hi) {
    ParticleStore& store = state_.store;
    const bool has_fluid = state_.has_fluid;
    // Fluid that arrives at run time: every pending particle, and every lattice particle of a
    // melting object (either may become fluid).
    long arriving = state_.counts.by_type[kPending];
    for (const SolidSetup& s : setup.solids)
        if (s.melts()) arriving += long(s.lattice.size());
    // The modules that register store fields with values of their own come first: the static
    // boundary's sort (sort_static) then permutes those values with the particles.
    NeighborSearch<Kernel>& search = add<NeighborSearch<Kernel>>(state_, lo, hi, arriving);
    SolidBodies& solids = add<SolidBodies>(device_);
    solids.init(setup, order, store);
    // The solids' walls: the domain's faces (in 2D its rectangle, open along z).
    Vec3 solid_lo = params_.domain_min, solid_hi = params_.domain_max;
    open_along_z_in_2d(solid_lo, solid_hi, Kernel::kDimensions);
    solids.plan(store, params_.gravity, solid_lo, solid_hi, has_fluid && params_.coupling.predict_solids,
                params_.solver.solid_substep);
    search.on_sorted([&solids, &store] {
        if (solids.active()) solids.update_slot_map(store);  // slot -> store index after the sort
    });
    BoundaryVolumes<Kernel>& volumes = add<BoundaryVolumes<Kernel>>(state_, setup, solids.active(), params_.heat.enabled);
    HeatConduction<Kernel>& heat = add<HeatConduction<Kernel>>(state_, setup, order, volumes, solids);
    add<PhaseChange>(device_, setup, store, solids, state_.counts, params_.fluid.rest_density, state_.fluid.mass);
    add<FluidEmitters>(device_, setup, store, state_.counts, params_.fluid.rest_density, params_.gravity);
    search.sort_static();
    const WallCorrection& walls = add<WallCorrection>(params_, has_fluid);
    Fluid<Kernel>& fluid = add<Fluid<Kernel>>(state_, volumes, walls, step_size_,
                                              InterfaceTension<Kernel>::needed(has_fluid, solids));
    add<InterfaceTension<Kernel>>(state_, volumes, fluid, solids);
    add<TwoWayCoupling<Kernel>>(state_, volumes, fluid, solids, search.uses_lists());
    add<PressureSensors<Kernel>>(state_, volumes, fluid, walls, setup, search.uses_lists());
    add<SolidCorrection<Kernel>>(state_, fluid, solids, walls);
    SurfaceField<Kernel>& surface = add<SurfaceField<Kernel>>(state_, search);
    add<Statistics<Kernel>>(state_, solids);
    search_ = &search;
    solids_ = &solids;
    heat_ = &heat;
    surface_ = &surface;
}

// `released`: this step's emitted particles, fluid now but sorted as inactive until the next step.
template <class Kernel>
void BackendSimulation<Kernel>::fill_report(const StepContext& step) {
    double stage_ms[kStageCount];
    timers_.read(stage_ms);
    const std::size_t fluid_count = step.ranges.fluid_end;
    report_.step = step_;
    report_.time = time_;
    report_.dt = step.dt;
    report_.iterations = step.iterations;
    report_.density_error_avg = fluid_count ? step.density_error.sum / double(fluid_count) : 0.0;
    report_.density_error_max = step.density_error.max;
    report_.max_speed = std::sqrt(double(step.fluid_motion.max_speed2));
    report_.kinetic_energy = step.fluid_motion.kinetic_energy;
    // The inactive group holds, besides lost fluid, the GPs and pending particles by design.
    const ParticleCounts& counts = state_.counts;
    const long inactive_by_design = counts.by_type[kGeometry] + counts.by_type[kPending] + step.released;
    report_.lost_particles = static_cast<long>(state_.store.moving_count() - step.ranges.solid_end) - inactive_by_design;
    report_.retries = step.retries;
    report_.diverged = step.outcome == PcisphOutcome::kDiverged;
    report_.unconverged = step.outcome == PcisphOutcome::kOutOfIterations;
    report_.solid_kinetic_energy = step.solid_motion.kinetic_energy;
    report_.solid_max_speed = std::sqrt(double(step.solid_motion.max_speed2));
    report_.columns.clear();
    for (const auto& m : modules_) m->report(report_.columns);
    report_.stage_ms.assign(stage_ms, stage_ms + plan_.size());
    report_.total_ms = 0;
    for (double ms : report_.stage_ms) report_.total_ms += ms;
}

template <class Kernel>
void BackendSimulation<Kernel>::report_non_finite(std::uint32_t index, const char* what) const {
    const ParticleStore& store = state_.store;
    std::uint32_t scene_index = 0;
    Vec3 x{0, 0, 0}, v{0, 0, 0};
    store.id.download_range(&scene_index, index, 1);
    store.position.download_range(&x, index, 1);
    store.velocity.download_range(&v, index, 1);
    char text[320];
    std::snprintf(text, sizeof text,
                  "step %ld (t = %.6g s): %s %u became non-finite or its speed overflowed (position %g %g %g, "
                  "velocity %g %g %g); try a smaller dt, or dt_mode \"cfl\"",
                  step_, time_, what, scene_index, double(x.x), double(x.y), double(x.z), double(v.x), double(v.y),
                  double(v.z));
    throw SimulationError(text);
}

template <class Kernel>
void BackendSimulation<Kernel>::download(HostParticles& out) const {
    device_.activate();
    const ParticleStore& store = state_.store;
    const std::size_t n = store.size();
    const std::size_t fluid_end = search_->last_ranges().fluid_end;
    const std::vector<std::uint32_t> id = store.id.to_host();
    const std::vector<Vec3> position = store.position.to_host(), velocity = store.velocity.to_host();
    const std::vector<Real> density = store.density.to_host(), pressure = store.pressure.to_host();
    const std::vector<std::uint8_t> type = store.type.to_host();
    const std::vector<std::int32_t> object = store.object.to_host();
    out.position.resize(n);
    out.velocity.resize(n);
    out.density.resize(n);
    out.pressure.resize(n);
    out.type.resize(n);
    out.object.resize(n);
    const DeviceArray<Real>* temperature_field = heat_->active() ? heat_->temperature() : nullptr;
    std::vector<Real> temperature;
    if (temperature_field) {
        temperature = temperature_field->to_host();
        out.temperature.resize(n);
    } else {
        out.temperature.clear();
    }
    // Back to the scene's order, so that frames and cross-backend comparisons line up.
    for (std::size_t k = 0; k < n; ++k) {
        const std::uint32_t i = id[k];
        const bool fluid = type[k] == kFluid && k < fluid_end;
        out.position[i] = position[k];
        out.velocity[i] = velocity[k];
        out.density[i] = fluid ? density[k] : state_.fluid.rest_density;
        out.pressure[i] = fluid ? pressure[k] : Real(0);
        out.type[i] = type[k];
        out.object[i] = object[k];
        if (temperature_field) out.temperature[i] = temperature[k];
    }
}

// What the next step reads that the setup does not give: the store's persistent fields (in their
// current order), each module's state, the clock and the step-size control. The grid, the lists
// and the boundary volumes are rebuilt by the next step; the static particles' volumes and cells,
// computed once from the setup, stay as the constructor made them.
template <class Kernel>
void BackendSimulation<Kernel>::save_state(StateArchive& out) const {
    device_.activate();
    state_.store.save(out);
    for (const auto& m : modules_) m->save(out);
    step_size_.save(out);
    out.put_value("time", time_);
    out.put_value("step", step_);
    out.put_value("last_max_speed", last_max_speed_);
}

template <class Kernel>
void BackendSimulation<Kernel>::load_state(const StateArchive& in) {
    device_.activate();
    ParticleStore& store = state_.store;
    // The static particles were placed by this simulation's setup, and their volumes and cells
    // computed from those places: a checkpoint whose static particles lie elsewhere belongs to
    // another scene (or another sampling), and loading it would pair its fluid with the wrong walls.
    store.check_counts(in);
    const std::size_t n = store.size(), moving = store.moving_count();
    const std::vector<Vec3> saved = in.get_sized<Vec3>("store.position", n);
    const std::vector<Vec3> built = store.position.to_host();
    if (std::memcmp(saved.data() + moving, built.data() + moving, (n - moving) * sizeof(Vec3)) != 0)
        throw InputError("checkpoint: its static boundary particles are not where this scene puts them; it was "
                         "written for another scene or by another version");
    for (const auto& m : modules_) m->check(in);
    store.load(in);
    // Counts by type from the loaded types (a particle may have changed type since the start).
    const std::vector<std::uint8_t> type = store.type.to_host();
    state_.counts = ParticleCounts{};
    for (std::uint8_t t : type) {
        if (t >= kParticleTypeCount) throw InputError("checkpoint: unknown particle type " + std::to_string(t));
        ++state_.counts.by_type[t];
    }
    for (const auto& m : modules_) m->load(in);
    step_size_.load(in);
    time_ = in.get_value<double>("time");
    step_ = in.get_value<long>("step");
    last_max_speed_ = in.get_value<double>("last_max_speed");
    const std::vector<std::string> names = report_.column_names;
    report_ = StepReport{};
    report_.column_names = names;
    report_.step = step_;
    report_.time = time_;
}

// The simulation for the scene's kernel and dimensions. The OpenMP backend instantiates each
// kernel in a source file of its own (simulation/instantiate_openmp*.cpp) so that they compile in
// parallel; a step then runs its kernel inline, with no branch on it.
std::unique_ptr<Simulation> make_cubic_spline_simulation(const SimulationSetup& setup, int threads);
std::unique_ptr<Simulation> make_wendland_c2_simulation(const SimulationSetup& setup, int threads);
std::unique_ptr<Simulation> make_cubic_spline_2d_simulation(const SimulationSetup& setup, int threads);
std::unique_ptr<Simulation> make_wendland_c2_2d_simulation(const SimulationSetup& setup, int threads);
inline std::unique_ptr<Simulation> make_simulation(const SimulationSetup& setup, int threads) {
    const bool wendland = setup.params.fluid.kernel == KernelKind::kWendlandC2;
    if (setup.params.dimensions == 2)
        return wendland ? make_wendland_c2_2d_simulation(setup, threads) : make_cubic_spline_2d_simulation(setup, threads);
    if (setup.params.dimensions != 3)
        throw InputError("simulation setup: dimensions must be 2 or 3, got " + std::to_string(setup.params.dimensions));
    if (wendland) return make_wendland_c2_simulation(setup, threads);
    return make_cubic_spline_simulation(setup, threads);
}

MW_BACKEND_END
