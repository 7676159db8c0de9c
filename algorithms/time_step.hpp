// One simulation on one backend. step() is the whole time step, top to bottom in the order of
// the method (METHOD.md, "One time step"); each stage is a named, timed call into algorithms/.
// Stages the scene does not need are not in the list: no launch, no memory.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "algorithms/coupling.hpp"
#include "algorithms/emitter.hpp"
#include "algorithms/heat.hpp"
#include "algorithms/melting.hpp"
#include "algorithms/interface_tension.hpp"
#include "algorithms/neighbor_grid.hpp"
#include "algorithms/neighbor_list.hpp"
#include "algorithms/particle_store.hpp"
#include "algorithms/pcisph.hpp"
#include "algorithms/pcisph_delta.hpp"
#include "algorithms/simulation.hpp"
#include "algorithms/solid_bodies.hpp"
#include "algorithms/state_archive.hpp"
#include "algorithms/step_size.hpp"
#include "algorithms/surface_field.hpp"

MW_BACKEND_BEGIN

// One class per smoothing kernel (sph_kernels.hpp); make_simulation() below picks the scene's.
template <class Kernel>
class BackendSimulation final : public Simulation {
   public:
    explicit BackendSimulation(const SimulationSetup& setup);

    void step() override {
        Real dt = step_size_.next(params_, last_max_speed_);

        // 1. Neighbour search: sort moving particles by cell, permute every field, cell ranges.
        timers_.start(kNeighbors);
        ranges_ = grid_.build(store_);
        if (solids_.active()) solids_.update_slot_map(store_);  // slot -> store index after the sort
        const std::size_t fluid_count = ranges_.fluid_end;
        const GridView grid = grid_.view();
        if (use_lists_) {
            // Pairs within h at the start of the step, as SPlisHSPlasH does. A pair that comes
            // within h while PCISPH predicts is left out: its weight is at most W(h - Δ), of order
            // (Δ/h)³, for the ≤ Δt·|v_i - v_j| it moved. A skin of 2 Δt v_max would have doubled
            // the lists (and the PCISPH time) in the fast phase of a dam break for no change in
            // the density error (measured: docs/solver.md).
            lists_.build(grid, fluid_count, store_.position.cview(), fluid_.kernel.h, neighbor_count_->view());
        }
        if (has_solid_contact_) mark_fluid_near_solids(fluid_count, grid, fluid_near_solid_.view());
        timers_.stop(kNeighbors);

        // 2. Boundary volumes of moving solids (static ones were computed once), and where PCISPH
        //    will meet them (pcisph.hpp, SolidLookahead: each soft object's mean velocity).
        if (has_solid_volumes_) {
            timers_.start(kSolidVolumes);
            compute_moving_solid_volumes(grid);
            if (predicts_solids_) lookahead_ = solids_.lookahead(store_, ranges_.solid_end);
            timers_.stop(kSolidVolumes);
        }

        // 3. Non-pressure forces: gravity, viscosity (Eq. 4, with the fluid's mirror images across
        //    the domain walls), wall friction (Eq. 8).
        if (has_viscosity_) {
            timers_.start(kViscosity);
            if (use_lists_)
                compute_viscosity_acceleration(lists_.view(), fluid_count, store_.position.cview(),
                                               store_.velocity.cview(), store_.density.cview(),
                                               boundary_volume_.cview(), nonpressure_.view(), fluid_);
            else
                compute_viscosity_acceleration(grid, fluid_count, store_.position.cview(), store_.velocity.cview(),
                                               store_.density.cview(), boundary_volume_.cview(), nonpressure_.view(),
                                               fluid_);
            timers_.stop(kViscosity);
        }
        //    Interface tension (Eq. 9): fluid drawn toward the surface particles of objects with an
        //    `interface_tension` (interface_tension.hpp).
        if (has_tension_) {
            timers_.start(kInterfaceTension);
            add_interface_tension(grid, fluid_count, store_.position.cview(), boundary_volume_.cview(),
                                  nonpressure_.view(), solids_.tension(store_), fluid_.kernel, fluid_.rest_density,
                                  fluid_.gravity, has_viscosity_);
            timers_.stop(kInterfaceTension);
        }
        const Vec3* nonpressure = has_viscosity_ || has_tension_ ? nonpressure_.view().data() : nullptr;
        // The moving solids' surface for the velocity–position correction (its position rule in
        // PCISPH, then the whole rule after the integration); none without it.
        SolidSurface solid_surface;
        if (has_solid_contact_) {
            solid_surface = solids_.surface(store_, grid, contact_band_, params_.fluid.spacing);
            solid_surface.fluid_near_solid = fluid_near_solid_.view().data();
        }

        // 4. PCISPH: predict, density, pressure, pressure force, until the average density
        //    error is below η (at least min, at most max iterations).
        //    In CFL mode a step whose iteration diverges is tried again from the same state at half
        //    the step (nothing before the integration has moved a particle): the CFL bound does
        //    not see a flat impact, where a whole column must stop at once (docs/solver.md).
        //    So is a step that ran out of iterations above the tolerance: a try that stalls
        //    short of it (most often under a low max_iterations) is solved at a shorter step,
        //    not integrated unconverged (docs/solver.md, "Sixteenth session").
        int iterations = 0, retries = 0;  // iterations: of every try of the step
        PcisphOutcome outcome = PcisphOutcome::kConverged;
        DensityError error;
        if (has_fluid_) {
            timers_.start(kPcisph);
            for (;;) {
                const Real delta = static_cast<Real>(delta_times_dt2_ / (double(dt) * double(dt)));
                // PCISPH meets the moving solids where this try's step will take them.
                if (predicts_solids_) lookahead_.dt = dt;
                int tried = 0;
                error = use_lists_ ? pcisph_iterations(lists_.view(), fluid_count, nonpressure, solid_surface, delta,
                                                       dt, tried, outcome)
                                   : pcisph_iterations(grid, fluid_count, nonpressure, solid_surface, delta, dt, tried,
                                                       outcome);
                iterations += tried;
                if (outcome == PcisphOutcome::kConverged || !StepSizeControl::may_retry(params_.solver, retries, dt))
                    break;
                dt *= Real(0.5);
                ++retries;
            }
            timers_.stop(kPcisph);
            // After a retry the next steps start from the step that held and grow back gradually.
            step_size_.after_step(retries, outcome == PcisphOutcome::kConverged, dt);
        }

        // 4b. Heat conduction (heat.hpp) over this step's neighbourhood: here, where the step's
        //     length is settled (PCISPH may have halved it) and nothing has moved yet.
        if (has_heat_) {
            timers_.start(kHeat);
            // No fluid: the solids' volumes are the heat's own to compute.
            if (solids_.active() && !has_solid_volumes_) compute_moving_solid_volumes(grid);
            const HeatMaterials materials = heat_materials();
            if (use_lists_)
                heat_.step(lists_.view(), grid, fluid_count, ranges_.solid_end, store_.position.cview(), materials,
                           temperature_->view(), dt, fluid_.kernel);
            else
                heat_.step(grid, grid, fluid_count, ranges_.solid_end, store_.position.cview(), materials,
                           temperature_->view(), dt, fluid_.kernel);
            timers_.stop(kHeat);
        }

        // 5. Two-way coupling: the reaction of every force the fluid felt from a moving solid's
        //    boundary particles, onto the solid's IBPs (coupling.hpp).
        if (has_coupling_) {
            timers_.start(kCoupling);
            CouplingData coupling = solids_.coupling();
            FluidPairs pairs;
            pairs.grid = grid;
            pairs.fluid_end = ranges_.fluid_end;
            pairs.solid_end = ranges_.solid_end;
            pairs.list_radius2 = use_lists_ ? fluid_.kernel.h * fluid_.kernel.h : Real(0);
            pairs.lookahead = lookahead_;
            coupling.inverse_dt = Real(1) / dt;
            fluid_reaction_on_solids(pairs, coupling, store_.position.cview(), store_.velocity.cview(),
                                     predicted_.cview(), boundary_volume_.cview(), pressure_term_.cview(), fluid_,
                                     has_viscosity_ && fluid_.wall_viscosity > Real(0));
            gather_solid_forces(coupling);
            timers_.stop(kCoupling);
        }
        // 6. Solids: LSM of the IBPs (forces, gravity, domain walls), then GPs (Eq. 19) and SBPs.
        SolidSummary solid_motion;
        if (solids_.active()) {
            timers_.start(kLsm);
            solid_motion = solids_.step(store_, dt, params_.gravity, params_.domain_min, params_.domain_max);
            timers_.stop(kLsm);
        }

        // 7. Integrate fluid (symplectic Euler) with the walls' correction; guard against NaN/inf;
        //    statistics (after the solids' correction where there is one: they describe the
        //    fluid the step ends with).
        MotionSummary motion;
        if (has_fluid_) {
            timers_.start(kIntegrate);
            integrate_fluid(fluid_count, store_.position.view(), store_.velocity.view(), nonpressure,
                            pressure_acc_.cview(), fluid_.gravity, dt, wall_contact_);
            if (!has_solid_contact_)
                motion = summarize_motion(fluid_count, store_.position.cview(), store_.velocity.cview(), fluid_.mass);
            timers_.stop(kIntegrate);
        }
        // 7b. The velocity–position correction against moving solids' SBPs (solid_contact.hpp).
        //     Two-way, each SBP gathers its share of the momentum from the fluid's state before
        //     the correction, so the corrected state goes to scratch first: the PCISPH loop's
        //     predictions and pressure accelerations, free until the next step's loop.
        if (has_solid_contact_) {
            timers_.start(kSolidContact);
            const SolidContactData contact =
                solids_.contact(solid_surface, params_.solid_slip, fluid_.mass, impulse_per_weight_.view().data());
            if (solids_.contact_takes_impulses()) {
                View<Vec3> corrected_position = predicted_.view(), corrected_velocity = pressure_acc_.view();
                correct_fluid_at_solids(fluid_count, store_.position.cview(), store_.velocity.cview(),
                                        corrected_position, corrected_velocity, contact, wall_contact_);
                gather_sbp_impulses(ranges_.fluid_end, ranges_.solid_end, store_.position.cview(), contact);
                apply_fluid_correction(fluid_count, corrected_position, corrected_velocity, store_.position.view(),
                                       store_.velocity.view());
            } else {
                correct_fluid_at_solids(fluid_count, store_.position.cview(), store_.velocity.cview(),
                                        store_.position.view(), store_.velocity.view(), contact, wall_contact_);
            }
            motion = summarize_motion(fluid_count, store_.position.cview(), store_.velocity.cview(), fluid_.mass);
            timers_.stop(kSolidContact);
        }

        // 8. Melting (melting.hpp): latent heat at the melting point, then the melting objects'
        //    SBPs that melt become fluid (the next step's sort moves them to the fluid's range),
        //    the IBPs they leave exposed become SBPs, and the regions are rebuilt.
        if (has_melting_) {
            timers_.start(kMelting);
            const PhaseChangeCounts changed = melting_.step(store_, solids_, *temperature_, fluid_.rest_density);
            counts_.by_type[kFluid] += changed.melted;
            counts_.by_type[kSurfaceBoundary] += changed.exposed - changed.melted;
            counts_.by_type[kInnerBoundary] -= changed.exposed;
            timers_.stop(kMelting);
        }

        // 9. Emitters (emitter.hpp): the layers due by the step's end leave their discs as fluid
        //    (the next step's sort moves them to the fluid's range).
        long released = 0;  // fluid now, but still among the inactive particles until the next sort
        if (has_emitters_) {
            timers_.start(kEmit);
            released =
                emitters_.step(store_, ranges_.solid_end, time_ + dt, params_.gravity, fluid_.rest_density, temperature_);
            counts_.by_type[kFluid] += released;
            counts_.by_type[kPending] -= released;
            timers_.stop(kEmit);
        }

        time_ += dt;
        ++step_;
        if (motion.first_bad != 0xffffffffu) report_non_finite(motion.first_bad);
        if (solid_motion.first_bad != 0xffffffffu)
            report_non_finite(solids_.store_index_of_slot(solid_motion.first_bad), "solid inner particle (IBP)");
        fill_report(dt, iterations, error, fluid_count, motion, released);
        report_.retries = retries;
        report_.heat_substeps = has_heat_ ? heat_.last_substeps() : 0;
        report_.heat_content = has_heat_ ? heat_.last_content() : 0.0;
        report_.melted = has_melting_ ? melting_.melted_total() : 0;
        report_.emitted = has_emitters_ ? emitters_.released_total() : 0;
        report_.diverged = outcome == PcisphOutcome::kDiverged;
        report_.unconverged = outcome == PcisphOutcome::kOutOfIterations;
        report_.solid_kinetic_energy = solid_motion.kinetic_energy;
        report_.solid_max_speed = std::sqrt(double(solid_motion.max_speed2));
        // The next CFL step bounds every moving particle's travel, a solid's as well as the
        // fluid's: a solid crossing resting fluid must not jump more than cfl r0 into it. (Its
        // IBPs' speed stands for its SBPs' and GPs', which are interpolated from them.)
        last_max_speed_ = std::max(report_.max_speed, report_.solid_max_speed);
        // ... and an emitter's new layers (released at its speed) too.
        if (has_emitters_) last_max_speed_ = std::max(last_max_speed_, emitters_.fastest_after(time_));
    }

    const StepReport& last_report() const override { return report_; }
    std::vector<std::string> stage_names() const override {
        std::vector<std::string> names;
        for (int stage : active_stages_) names.push_back(kStageNames[stage]);
        return names;
    }
    void download(HostParticles& out) const override;
    void fluid_color_field(const SurfaceNodes& nodes, std::vector<Real>& color, double& iso) override;
    ParticleCounts counts() const override { return counts_; }
    // Everything this simulation holds on the device, and the backend's shared scratch (the
    // sort's buffers, sized by the largest sort of the process so far).
    std::size_t device_bytes() const override {
        return store_.bytes() + grid_.bytes() + lists_.bytes() + boundary_volume_.bytes() + nonpressure_.bytes() +
               pressure_acc_.bytes() + pressure_term_.bytes() + predicted_.bytes() + solids_.bytes() +
               contact_boxes_.bytes() + contact_objects_.bytes() + contact_object_distances_.bytes() +
               impulse_per_weight_.bytes() + fluid_near_solid_.bytes() + heat_.bytes() + melting_.bytes() +
               emitters_.bytes() + color_field_.bytes() + backend_scratch_bytes();
    }
    double time() const override { return time_; }
    int heat_substeps_needed(double dt) const override { return has_heat_ ? heat_.substeps_needed(dt) : 0; }
    std::string backend_name() const override { return kBackendName; }
    std::string device_name() const override { return device_description(); }
    std::vector<std::array<double, 3>> fluid_force_on_solids() const override { return solids_.object_forces(); }
    std::vector<std::array<double, 3>> pending_contact_impulse() const override {
        return solids_.object_contact_impulses();
    }
    void save_state(StateArchive& out) const override;
    void load_state(const StateArchive& in) override;

   private:
    // The PCISPH loop over a neighbourhood (the grid, or this step's lists): predict, density and
    // pressure, error, pressure force; until the average error is below η, and the largest below
    // eta_max when that is set (min/max iterations).
    // `outcome`: converged (below the tolerance), diverged, or out of iterations above it.
    // Diverged: the average error rose to more than twice the lowest it reached in this step and
    // to more than twice η (or, with eta_max, the largest error did, against eta_max). PCISPH's
    // pressure then overshoots and feeds on itself; iterating on only throws the fluid apart, so
    // the loop stops there. The lowest may have been within the tolerance: in a 4.8 ms step of
    // the dam break at CFL 1 the peak sat at 4.7-4.9% (eta_max 5%) while the average crept down
    // to 1.0%, then the peak rose to 24% within three iterations and 154% within eight; a test
    // that asked the lowest to be above the tolerance let that run on to max_iterations
    // (docs/solver.md, "Sixteenth session").
    enum class PcisphOutcome { kConverged, kDiverged, kOutOfIterations };
    template <class Neighbors>
    DensityError pcisph_iterations(const Neighbors& neighbors, std::size_t fluid_count, const Vec3* nonpressure,
                                   const SolidSurface& solid_surface, Real delta, Real dt, int& iterations,
                                   PcisphOutcome& outcome) {
        const SolverParams& solver = params_.solver;
        DensityError error;
        iterations = 0;
        outcome = PcisphOutcome::kOutOfIterations;
        double lowest_average = 1e300, lowest_peak = 1e300;
        while (iterations < solver.max_iterations) {
            // The first prediction has no pressure acceleration yet (nothing to clear beforehand).
            const bool first = iterations == 0;
            predict_positions(fluid_count, store_.position.cview(), store_.velocity.cview(), nonpressure,
                              first ? nullptr : pressure_acc_.view().data(), predicted_.view(), fluid_.gravity, dt,
                              wall_contact_, solid_surface);
            predict_density_and_pressure(neighbors, fluid_count, predicted_.cview(), store_.position.cview(), lookahead_,
                                         boundary_volume_.cview(), store_.density.view(), store_.pressure.view(),
                                         pressure_term_.view(), fluid_, delta, first);
            pressure_acceleration(neighbors, fluid_count, predicted_.cview(), store_.position.cview(), lookahead_,
                                  boundary_volume_.cview(), pressure_term_.cview(), pressure_acc_.view(), fluid_);
            ++iterations;
            // The error is a reduction read back by the host (a synchronisation on a GPU), so it is
            // computed only where it can end the loop: from the min_iterations-th iteration on. It
            // comes after the pressure force, which does not change the densities, so the force
            // kernel is already queued while the host waits.
            if (iterations < solver.min_iterations && iterations < solver.max_iterations) continue;
            error = density_error(fluid_count, store_.density.cview(), fluid_.rest_density);
            const double average = fluid_count ? error.sum / double(fluid_count) : 0.0;
            const bool peak_ok = solver.eta_max <= 0 || error.max <= solver.eta_max;
            if (average <= solver.eta && peak_ok) {
                outcome = PcisphOutcome::kConverged;
                break;
            }
            lowest_average = std::min(lowest_average, average);
            lowest_peak = std::min(lowest_peak, double(error.max));
            if ((average > 2 * lowest_average && average > 2 * solver.eta) ||
                (solver.eta_max > 0 && error.max > 2 * lowest_peak && error.max > 2 * solver.eta_max)) {
                outcome = PcisphOutcome::kDiverged;
                break;
            }
        }
        return error;
    }

    enum Stage {
        kNeighbors,
        kSolidVolumes,
        kViscosity,
        kInterfaceTension,
        kPcisph,
        kHeat,
        kCoupling,
        kLsm,
        kIntegrate,
        kSolidContact,
        kMelting,
        kEmit,
        kStageCount
    };
    static constexpr const char* kStageNames[kStageCount] = {
        "neighbors", "solid_volumes", "viscosity", "interface_tension", "pcisph", "heat",
        "coupling",  "lsm",           "integrate", "solid_contact",     "melting", "emit"};

    // `released`: this step's emitted particles, fluid now but sorted as inactive until the next step.
    void fill_report(Real dt, int iterations, const DensityError& error, std::size_t fluid_count,
                     const MotionSummary& motion, long released) {
        double stage_ms[kStageCount];
        timers_.read(stage_ms);
        report_.step = step_;
        report_.time = time_;
        report_.dt = dt;
        report_.iterations = iterations;
        report_.density_error_avg = fluid_count ? error.sum / double(fluid_count) : 0.0;
        report_.density_error_max = error.max;
        report_.max_speed = std::sqrt(double(motion.max_speed2));
        report_.kinetic_energy = motion.kinetic_energy;
        // The inactive group holds, besides lost fluid, the GPs and pending particles by design.
        const long inactive_by_design = counts_.by_type[kGeometry] + counts_.by_type[kPending] + released;
        report_.lost_particles = static_cast<long>(store_.moving_count() - ranges_.solid_end) - inactive_by_design;
        report_.stage_ms.clear();
        report_.total_ms = 0;
        for (int stage : active_stages_) {
            report_.stage_ms.push_back(stage_ms[stage]);
            report_.total_ms += stage_ms[stage];
        }
    }

    // V_b of the moving solids' boundary particles (static ones are computed once).
    void compute_moving_solid_volumes(const GridView& grid) {
        compute_boundary_volumes(grid, store_.position.cview(), boundary_volume_.view(), ranges_.fluid_end,
                                 ranges_.solid_end - ranges_.fluid_end, true, fluid_.kernel);
    }

    // Where the heat stage finds each particle's material and volume (heat.hpp).
    HeatMaterials heat_materials() const {
        HeatMaterials m;
        m.type = store_.type.cview();
        m.density = store_.density.cview();
        m.boundary_volume = boundary_volume_.cview();
        m.fluid = HeatMaterial{params_.heat.fluid_diffusivity, params_.heat.fluid_capacity};
        m.fluid_mass = fluid_.mass;
        m.rest_density = fluid_.rest_density;
        m.latent = melting_.latent();
        solids_.describe_heat(m);
        return m;
    }

    void report_non_finite(std::uint32_t index, const char* what = "fluid particle") const {
        std::uint32_t scene_index = 0;
        Vec3 x{0, 0, 0}, v{0, 0, 0};
        store_.id.download_range(&scene_index, index, 1);
        store_.position.download_range(&x, index, 1);
        store_.velocity.download_range(&v, index, 1);
        char text[320];
        std::snprintf(text, sizeof text,
                      "step %ld (t = %.6g s): %s %u became non-finite or its speed overflowed (position %g "
                      "%g %g, velocity %g %g %g); try a smaller dt, or dt_mode \"cfl\"",
                      step_, time_, what, scene_index, double(x.x), double(x.y), double(x.z), double(v.x), double(v.y),
                      double(v.z));
        throw SimulationError(text);
    }

    // First, so that it goes last: the backend frees its shared scratch when no simulation is left.
    ScratchUser scratch_user_;
    SimulationParams params_;
    FluidConstants<Kernel> fluid_;
    double delta_times_dt2_ = 0;  // δ·Δt², from the prototype lattice
    ParticleStore store_;
    NeighborGrid grid_;
    NeighborList lists_;
    bool use_lists_ = false;
    WallContact wall_contact_;  // the velocity–position correction against the walls, static boxes and objects
    DeviceArray<ContactBox> contact_boxes_;  // the static boxes' faces, read by wall_contact_
    DeviceArray<ContactField> contact_objects_;     // static mesh objects' distance grids, read by wall_contact_
    DeviceArray<Real> contact_object_distances_;    // ... and their values
    DeviceArray<std::uint32_t>* neighbor_count_ = nullptr;  // store field: each particle's list length, sizes next step's row
    GroupRanges ranges_;
    DeviceArray<Real> boundary_volume_;  // V_b, indexed like the store (fluid entries unused)
    DeviceArray<Vec3> nonpressure_;      // gravity + viscosity; only when μ > 0
    DeviceArray<Vec3> pressure_acc_;
    DeviceArray<Real> pressure_term_;  // p/ρ² of this iteration
    DeviceArray<Vec3> predicted_;
    StageTimers timers_{kStageCount};
    std::vector<int> active_stages_;
    bool has_viscosity_ = false;
    bool has_tension_ = false;  // an object with interface tension, and fluid
    bool has_fluid_ = false;
    bool has_solid_volumes_ = false;  // moving solids and fluid: boundary volumes every step
    bool has_coupling_ = false;       // ... and two-way coupling: the fluid's forces act on them
    bool has_solid_contact_ = false;  // ... and the velocity–position correction against them
    // ... and PCISPH meets them where they will be (pcisph.hpp, SolidLookahead), this try's.
    bool predicts_solids_ = false;
    SolidLookahead lookahead_;
    DeviceArray<Vec3> impulse_per_weight_;  // the correction's, per fluid particle (two-way only)
    DeviceArray<std::uint8_t> fluid_near_solid_;  // its gathers' mask, per fluid particle (virtual_boundary.hpp)
    Real contact_band_ = 0;                 // its band c, m
    SolidBodies solids_;
    bool has_heat_ = false;                     // heat conduction (heat.hpp)
    DeviceArray<Real>* temperature_ = nullptr;  // its store field
    HeatConduction heat_;
    bool has_melting_ = false;  // an object melts (melting.hpp)
    PhaseChange melting_;
    bool has_emitters_ = false;  // fluid emitters (emitter.hpp)
    FluidEmitters emitters_;
    ParticleCounts counts_;
    double time_ = 0;
    long step_ = 0;
    double last_max_speed_ = 0;
    StepSizeControl step_size_;  // CFL mode: the bound, and the limit PCISPH retries set
    StepReport report_;
    // Surface reconstruction at frame times (surface_field.hpp): the colour field at its nodes,
    // sized by the largest node box asked for so far.
    DeviceArray<Real> color_field_;
};

template <class Kernel>
BackendSimulation<Kernel>::BackendSimulation(const SimulationSetup& setup) : params_(setup.params) {
    const std::size_t n = setup.position.size();
    if (setup.velocity.size() != n || setup.type.size() != n || setup.object.size() != n)
        throw InputError("simulation setup: position, velocity, type and object lists differ in length");
    const FluidParams& fp = params_.fluid;
    if (!(fp.spacing > 0) || !(fp.support_radius > fp.spacing) || !(fp.rest_density > 0))
        throw InputError("simulation setup: need spacing > 0, support_radius > spacing, rest_density > 0");

    // Moving particles first, static boundary last (stable, so ids keep the scene's order).
    std::vector<std::uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::stable_partition(order.begin(), order.end(),
                          [&](std::uint32_t i) { return setup.type[i] != kStaticBoundary; });
    std::size_t moving = 0;
    std::vector<Vec3> position(n), velocity(n);
    std::vector<std::uint8_t> type(n);
    std::vector<std::int32_t> object(n);
    Vec3 lo = params_.domain_min, hi = params_.domain_max;
    for (std::size_t k = 0; k < n; ++k) {
        const std::uint32_t i = order[k];
        position[k] = setup.position[i];
        velocity[k] = setup.velocity[i];
        type[k] = setup.type[i];
        object[k] = setup.object[i];
        if (type[k] >= kParticleTypeCount)
            throw InputError("simulation setup: unknown particle type " + std::to_string(type[k]));
        if (type[k] != kStaticBoundary) ++moving;
        ++counts_.by_type[type[k]];
        if (!is_finite(position[k]) || !is_finite(velocity[k]))
            throw InputError("simulation setup: particle " + std::to_string(i) +
                             " has a non-finite position or velocity");
        if (type[k] == kStaticBoundary) {  // the grid must hold every static particle
            lo = Vec3{std::min(lo.x, position[k].x), std::min(lo.y, position[k].y), std::min(lo.z, position[k].z)};
            hi = Vec3{std::max(hi.x, position[k].x), std::max(hi.y, position[k].y), std::max(hi.z, position[k].z)};
        }
    }

    store_.resize(n, moving);
    store_.id.upload(order);
    store_.position.upload(position);
    store_.velocity.upload(velocity);
    store_.type.upload(type);
    store_.object.upload(object);
    store_.density.fill(fp.rest_density);
    store_.pressure.fill(Real(0));
    solids_.init(setup, order, store_);  // the solid_slot field, regions, interpolation links
    has_heat_ = params_.heat.enabled;
    if (has_heat_) {
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
        if (!(params_.heat.fluid_diffusivity >= 0) || !std::isfinite(double(params_.heat.fluid_diffusivity)))
            throw InputError("simulation setup: the fluid's thermal diffusivity must be finite and >= 0");
        if (!(params_.heat.fluid_capacity > 0) || !std::isfinite(double(params_.heat.fluid_capacity)))
            throw InputError("simulation setup: the fluid's heat capacity must be finite and > 0");
        for (const SolidSetup& solid : setup.solids) {
            if (!(solid.thermal_diffusivity >= 0) || !std::isfinite(double(solid.thermal_diffusivity)))
                throw InputError("simulation setup: solid \"" + solid.name +
                                 "\" has a thermal diffusivity that is not finite and >= 0");
            if (!(solid.heat_capacity > 0) || !std::isfinite(double(solid.heat_capacity)))
                throw InputError("simulation setup: solid \"" + solid.name +
                                 "\" has a heat capacity that is not finite and > 0");
        }
        if (params_.heat.max_substeps < 1)
            throw InputError("simulation setup: heat conduction needs max_substeps >= 1");
        temperature_ = &store_.add<Real>("temperature", FieldLife::kPersistent);
        temperature_->upload(temperature);
    }
    melting_.init(setup, store_, solids_);
    has_melting_ = melting_.active();
    emitters_.init(setup, fp.spacing);
    has_emitters_ = emitters_.active();
    // A scene whose objects melt, or with an emitter, gains fluid: its fluid stages run from the start.
    const bool holds_fluid = counts_.by_type[kFluid] > 0 || has_melting_ || has_emitters_;

    // The grid covers the domain, its walls and one support radius more; fluid that leaves it is
    // counted as lost.
    const Real h = fp.support_radius;
    grid_.configure(Vec3{lo.x - h, lo.y - h, lo.z - h}, Vec3{hi.x + h, hi.y + h, hi.z + h}, h, params_.ordering,
                    params_.cells_per_support);
    grid_.build_static(store_);

    fluid_.kernel = Kernel::with_support(h);
    fluid_.rest_density = fp.rest_density;
    fluid_.viscosity = fp.viscosity;
    fluid_.wall_viscosity = fp.wall_viscosity;
    fluid_.gravity = params_.gravity;
    if (params_.domain_walls && params_.wall_correction) {
        if (!(params_.wall_gap >= 0))
            throw InputError("simulation setup: the domain walls' correction needs the walls' gap (params.wall_gap)");
        wall_contact_ = WallContact::for_domain(params_.domain_min, params_.domain_max, params_.wall_gap, fp.spacing);
    }
    if (params_.wall_correction && !params_.static_boxes.empty() && holds_fluid) {
        contact_boxes_.upload(params_.static_boxes);
        wall_contact_.boxes = contact_boxes_.cview();
    }
    if (params_.wall_correction && !params_.static_objects.empty() && holds_fluid) {
        std::size_t values = 0;
        for (const ContactField& c : params_.static_objects) {
            if (c.field.nx < 2 || c.field.ny < 2 || c.field.nz < 2 || !(c.field.inv_spacing > 0))
                throw InputError("simulation setup: a static object's distance grid needs 2 nodes or more per axis "
                                 "and a positive spacing");
            values = std::max(values, std::size_t(c.field.first) + std::size_t(c.field.nx) * std::size_t(c.field.ny) *
                                                                      std::size_t(c.field.nz));
        }
        if (values > params_.static_object_distances.size())
            throw InputError("simulation setup: a static object's distance grid reaches past the values given");
        contact_objects_.upload(params_.static_objects);
        contact_object_distances_.upload(params_.static_object_distances);
        wall_contact_.objects = contact_objects_.cview();
        wall_contact_.object_distances = contact_object_distances_.cview();
    }
    if (params_.domain_walls && fp.viscosity > 0)
        fluid_.mirrors = WallMirrors{params_.domain_min, params_.domain_max, WallMirrors::kAllFaces, h};
    // Mass such that the prototype lattice at spacing r0 has exactly the rest density.
    const PrototypeSums sums = prototype_sums(fluid_.kernel, fp.spacing, 3);
    fluid_.mass = static_cast<Real>(fp.rest_density / sums.sum_W);
    delta_times_dt2_ = pcisph_delta(sums, fp.rest_density, fluid_.mass, 1.0);
    // Brookshaw's Laplacian, rescaled to be exact on the same lattice (heat.hpp).
    if (has_heat_) heat_.init(moving, params_.heat.max_substeps, heat_lattice_scale(sums));

    has_fluid_ = holds_fluid;  // a solids-only scene runs no fluid stage
    use_lists_ = has_fluid_ && (params_.neighbor_lists == SimulationParams::Lists::kAuto
                                    ? kPrefersNeighborLists
                                    : params_.neighbor_lists == SimulationParams::Lists::kOn);
    if (use_lists_) {
        // Registered before the first sort, so that it travels with the particles from the start;
        // 0 makes the first build lay its rows out from exact counts (one second fill).
        neighbor_count_ = &store_.add<std::uint32_t>("neighbor_count", FieldLife::kPersistent);
        neighbor_count_->fill(0);
    }
    has_viscosity_ = has_fluid_ && (fp.viscosity > 0 || (fp.wall_viscosity > 0 && store_.static_count() > 0));
    has_solid_volumes_ = solids_.active() && has_fluid_;
    has_coupling_ = has_solid_volumes_ && solids_.coupled();
    has_tension_ = has_solid_volumes_ && solids_.has_tension();
    has_solid_contact_ = has_solid_volumes_ && params_.solid_correction;
    predicts_solids_ = has_solid_volumes_ && params_.solid_prediction;
    contact_band_ = static_cast<Real>(kMovingSolidContact * fp.spacing);
    if (!(params_.solid_slip >= 0 && params_.solid_slip <= 1))
        throw InputError("simulation setup: the solids' slip factor must be in [0, 1]");

    // Boundary volumes only matter to fluid next to boundary particles: without fluid, or without
    // any boundary particle, they are neither stored nor computed. They are indexed like the store
    // (fluid entries unused) so that a particle changing type (melting) needs no re-indexing.
    if (has_fluid_) {
        if (store_.static_count() || solids_.active()) boundary_volume_.resize(n);
        if (store_.static_count())
            compute_boundary_volumes(grid_.view(), store_.position.cview(), boundary_volume_.view(), moving,
                                     store_.static_count(), false, fluid_.kernel);
        pressure_acc_.resize(moving);
        pressure_term_.resize(moving);
        predicted_.resize(moving);
    }
    if (has_viscosity_ || has_tension_) nonpressure_.resize(moving);
    if (has_heat_ && solids_.active() && boundary_volume_.size() == 0) boundary_volume_.resize(n);
    if (has_solid_contact_ && solids_.contact_takes_impulses()) impulse_per_weight_.resize(moving);
    if (has_solid_contact_) fluid_near_solid_.resize(moving);

    active_stages_.push_back(kNeighbors);
    if (has_solid_volumes_) active_stages_.push_back(kSolidVolumes);
    if (has_viscosity_) active_stages_.push_back(kViscosity);
    if (has_tension_) active_stages_.push_back(kInterfaceTension);
    if (has_fluid_) active_stages_.push_back(kPcisph);
    if (has_heat_) active_stages_.push_back(kHeat);
    if (has_coupling_) active_stages_.push_back(kCoupling);
    if (solids_.active()) active_stages_.push_back(kLsm);
    if (has_fluid_) active_stages_.push_back(kIntegrate);
    if (has_solid_contact_) active_stages_.push_back(kSolidContact);
    if (has_melting_) active_stages_.push_back(kMelting);
    if (has_emitters_) active_stages_.push_back(kEmit);

    // One neighbour build now, so that every per-step buffer (sort keys, lists) is allocated
    // before the first step and device_bytes() is the steady-state figure `info` reports.
    ranges_ = grid_.build(store_);
    if (solids_.active()) solids_.update_slot_map(store_);
    if (use_lists_) {
        lists_.build(grid_.view(), ranges_.fluid_end, store_.position.cview(), fluid_.kernel.h, neighbor_count_->view());
        // Fluid that arrives at run time gets rows without reallocating: every pending particle,
        // and every lattice particle of a melting object.
        const long arriving = counts_.by_type[kPending] + (has_melting_ ? melting_.lattice_particles() : 0);
        if (arriving > 0) lists_.reserve(ranges_.fluid_end + std::size_t(arriving));
    }
    // The heat's sub-steps from the particles as they start: the solids' g can exceed a fluid
    // lattice's (heat.hpp, calibrate).
    if (has_heat_) {
        if (solids_.active()) compute_moving_solid_volumes(grid_.view());
        heat_.calibrate(grid_.view(), ranges_.fluid_end, ranges_.solid_end, store_.position.cview(), heat_materials(),
                        fluid_.kernel);
    }

    // The reductions a step reads back (the density error, the motion summaries) make their
    // workspaces on first use: on a GPU a device result, a pinned host slot and CUB's temporary
    // storage, on CPU cores the per-chunk partials. One call of each here, so that the first step
    // allocates nothing either.
    if (has_fluid_) {
        density_error(ranges_.fluid_end, store_.density.cview(), fluid_.rest_density);
        summarize_motion(ranges_.fluid_end, store_.position.cview(), store_.velocity.cview(), fluid_.mass);
    }
    if (solids_.active()) solids_.summary(store_);

    // The first CFL step uses the initial speeds, and the emitters'.
    double max_speed2 = 0;
    for (std::size_t k = 0; k < moving; ++k) max_speed2 = std::max(max_speed2, double(norm2(velocity[k])));
    last_max_speed_ = std::sqrt(max_speed2);
    if (has_emitters_) last_max_speed_ = std::max(last_max_speed_, emitters_.fastest_after(0));
}

template <class Kernel>
void BackendSimulation<Kernel>::download(HostParticles& out) const {
    const std::size_t n = store_.size();
    const std::vector<std::uint32_t> id = store_.id.to_host();
    const std::vector<Vec3> position = store_.position.to_host(), velocity = store_.velocity.to_host();
    const std::vector<Real> density = store_.density.to_host(), pressure = store_.pressure.to_host();
    const std::vector<std::uint8_t> type = store_.type.to_host();
    const std::vector<std::int32_t> object = store_.object.to_host();
    out.position.resize(n);
    out.velocity.resize(n);
    out.density.resize(n);
    out.pressure.resize(n);
    out.type.resize(n);
    out.object.resize(n);
    std::vector<Real> temperature;
    if (temperature_) {
        temperature = temperature_->to_host();
        out.temperature.resize(n);
    } else {
        out.temperature.clear();
    }
    // Back to the scene's order, so that frames and cross-backend comparisons line up.
    for (std::size_t k = 0; k < n; ++k) {
        const std::uint32_t i = id[k];
        const bool fluid = type[k] == kFluid && k < ranges_.fluid_end;
        out.position[i] = position[k];
        out.velocity[i] = velocity[k];
        out.density[i] = fluid ? density[k] : fluid_.rest_density;
        out.pressure[i] = fluid ? pressure[k] : Real(0);
        out.type[i] = type[k];
        out.object[i] = object[k];
        if (temperature_) out.temperature[i] = temperature[k];
    }
}

template <class Kernel>
void BackendSimulation<Kernel>::fluid_color_field(const SurfaceNodes& nodes, std::vector<Real>& color, double& iso) {
    // The particles have moved since this step's build; a build now (a stable sort by the keys the
    // next step would compute) leaves the next step's build nothing to reorder.
    ranges_ = grid_.build(store_);
    if (solids_.active()) solids_.update_slot_map(store_);
    color_field_.resize(nodes.count());
    // The mass is ρ0 over the lattice's Σ W (pcisph_delta.hpp): m / ρ0 normalises the field.
    compute_color_field(grid_.view(), store_.position.cview(), fluid_.kernel, fluid_.mass / fluid_.rest_density, nodes,
                        color_field_.view());
    color_field_.download(color);
    iso = surface_iso_value(fluid_.kernel, double(params_.fluid.spacing));  // a few thousand kernel values
}

// What the next step reads that the setup does not give: the store's persistent fields (in their
// current order), the solids' state, the clock and the step-size control. The grid, the lists and
// the boundary volumes are rebuilt by the next step; the static particles' volumes and cells,
// computed once from the setup, stay as the constructor made them.
template <class Kernel>
void BackendSimulation<Kernel>::save_state(StateArchive& out) const {
    store_.save(out);
    solids_.save(out);
    emitters_.save(out);
    step_size_.save(out);
    out.put_value("time", time_);
    out.put_value("step", step_);
    out.put_value("last_max_speed", last_max_speed_);
}

template <class Kernel>
void BackendSimulation<Kernel>::load_state(const StateArchive& in) {
    // The static particles were placed by this simulation's setup, and their volumes and cells
    // computed from those places: a checkpoint whose static particles lie elsewhere belongs to
    // another scene (or another sampling), and loading it would pair its fluid with the wrong walls.
    store_.check_counts(in);
    const std::size_t n = store_.size(), moving = store_.moving_count();
    const std::vector<Vec3> saved = in.get_sized<Vec3>("store.position", n);
    const std::vector<Vec3> built = store_.position.to_host();
    if (std::memcmp(saved.data() + moving, built.data() + moving, (n - moving) * sizeof(Vec3)) != 0)
        throw InputError("checkpoint: its static boundary particles are not where this scene puts them; it was "
                         "written for another scene or by another version");
    // The lists' row counts only size the next layout: a checkpoint from a backend without lists
    // starts them from 0, as the first step of a run does (one second fill).
    if (temperature_ && !in.has("store.temperature"))
        throw InputError("checkpoint: it holds no temperatures, and this scene conducts heat (heat.enabled); it was "
                         "written for another scene");
    store_.load(in, {"neighbor_count"});
    if (neighbor_count_ && !in.has("store.neighbor_count")) neighbor_count_->fill(0);
    solids_.load(in);
    melting_.load(store_, solids_);  // the slots left, and their regions, from the loaded slots
    emitters_.load(in);
    step_size_.load(in);
    time_ = in.get_value<double>("time");
    step_ = in.get_value<long>("step");
    last_max_speed_ = in.get_value<double>("last_max_speed");
    // Counts by type from the loaded types (a particle may have changed type since the start).
    const std::vector<std::uint8_t> type = store_.type.to_host();
    counts_ = ParticleCounts{};
    for (std::uint8_t t : type) {
        if (t >= kParticleTypeCount) throw InputError("checkpoint: unknown particle type " + std::to_string(t));
        ++counts_.by_type[t];
    }
    if (counts_.by_type[kPending] != emitters_.capacity() - emitters_.released_total())
        throw InputError("checkpoint: its pending particles do not match its emitters' released layers");
    report_ = StepReport{};
    report_.step = step_;
    report_.time = time_;
}

// The simulation for the scene's kernel. Each kernel's instantiation has a source file of its own
// in each backend (simulation_<backend>.cpp/.cu for the cubic spline, *_wendland for Wendland C2),
// so that the two compile in parallel; a step then runs its kernel inline, with no branch on it.
std::unique_ptr<Simulation> make_cubic_spline_simulation(const SimulationSetup& setup);
std::unique_ptr<Simulation> make_wendland_c2_simulation(const SimulationSetup& setup);
inline std::unique_ptr<Simulation> make_simulation(const SimulationSetup& setup) {
    if (setup.params.fluid.kernel == KernelKind::kWendlandC2) return make_wendland_c2_simulation(setup);
    return make_cubic_spline_simulation(setup);
}

MW_BACKEND_END
