// The fluid module: PCISPH (Solenthaler & Pajarola 2009) with Akinci boundaries, its kernels in
// pcisph.hpp. Three stages: "viscosity" (non-pressure forces), "pcisph" (the pressure solve, with
// the step's halving in CFL mode) and "integrate" (symplectic Euler and the walls' correction).
#pragma once
#include <algorithm>
#include <stdexcept>

#include "algorithms/boundary_volumes.hpp"
#include "algorithms/module.hpp"
#include "algorithms/step_size.hpp"
#include "algorithms/wall_correction.hpp"

MW_BACKEND_BEGIN

template <class Kernel>
class Fluid final : public Module {
   public:
    // `tension`: interface tension adds to the non-pressure forces (interface_tension.hpp).
    Fluid(SimulationState<Kernel>& state, const BoundaryVolumes<Kernel>& volumes, const WallCorrection& walls,
          StepSizeControl& step_size, bool tension)
        : state_(state), volumes_(volumes), walls_(walls), step_size_(step_size) {
        if (!state.has_fluid) return;
        const FluidParams& fp = state.params.fluid;
        const std::size_t moving = state.store.moving_count();
        // Friction (Eq. 8) acts against every boundary particle, static or of a moving solid.
        const bool boundary = state.store.static_count() > 0 || volumes.moving_solids();
        has_viscosity_ = fp.viscosity > 0 || (fp.wall_viscosity > 0 && boundary);
        pressure_acc_.resize(moving);
        pressure_term_.resize(moving);
        predicted_.resize(moving);
        if (has_viscosity_ || tension) nonpressure_.resize(moving);
        // One place per particle of the solids' group (SBPs and IBPs): melting and particles lost
        // from the grid only ever shrink it.
        if (volumes.moving_solids())
            solid_met_.resize(state.counts.by_type[kSurfaceBoundary] + state.counts.by_type[kInnerBoundary]);
    }

    void bind(StepPlan& plan) override {
        if (!state_.has_fluid) return;
        if (has_viscosity_) plan.bind("viscosity", [this](StepContext& step) { viscosity(step); });
        plan.bind("pcisph", [this](StepContext& step) { solve(step); });
        plan.bind("integrate", [this](StepContext& step) { integrate(step); });
    }

    // The density error's reduction makes its workspace on first use: once here, before the first step.
    void start(const StepContext& first) override {
        if (!state_.has_fluid) return;
        density_error(state_.device, first.ranges.fluid_end, state_.store.density.cview(), state_.fluid.rest_density);
    }

    // Gravity, viscosity (Eq. 4, with the fluid's mirror images across the domain walls) and
    // friction with boundary particles (Eq. 8).
    void viscosity(StepContext& step) {
        const ParticleStore& store = state_.store;
        step.neighbors.visit([&](const auto& rows) {
            compute_viscosity_acceleration(state_.device, rows, step.ranges.fluid_end, store.position.cview(),
                                           store.velocity.cview(), store.density.cview(), volumes_.volumes(),
                                           nonpressure_.view(), state_.fluid);
        });
        step.nonpressure = nonpressure_.view().data();
    }

    // PCISPH: predict, density, pressure, pressure force, until the average density error is below
    // eta (at least min, at most max iterations). In CFL mode a step whose iteration diverges is
    // tried again from the same state at half the step (nothing before the integration has moved a
    // particle): the CFL bound does not see a flat impact, where a whole column must stop at once
    // (docs/solver.md). So is a step that ran out of iterations above the tolerance: a try that
    // stalls short of it (most often under a low max_iterations) is solved at a shorter step, not
    // integrated unconverged.
    void solve(StepContext& step) {
        const auto attempt = [&](Real length) {
            const Real delta = static_cast<Real>(state_.delta_times_dt2 / (double(length) * double(length)));
            step.lookahead.dt = length;  // PCISPH meets the moving solids where this try's step takes them
            int tried = 0;
            step.neighbors.visit([&](const auto& rows) { iterate(rows, step, delta, length, tried); });
            step.iterations += tried;
        };
        Real dt = step.dt;
        bool every_try_diverged = true;
        for (;;) {
            attempt(dt);
            every_try_diverged = every_try_diverged && step.outcome == PcisphOutcome::kDiverged;
            if (step.outcome == PcisphOutcome::kConverged ||
                !StepSizeControl::may_retry(state_.params.solver, step.retries, dt))
                break;
            dt *= Real(0.5);
            ++step.retries;
        }
        if (every_try_diverged && step.retries > 0) {
            // Every halving diverged as well: the step starts from a state compressed beyond what
            // a shorter step undoes, and at dt/2^k the pressure that undoes it becomes a velocity
            // 2^k times larger (a 2 m/s stream meeting a wall: 778 m/s after six halvings). The
            // step is taken at its first try's length, as fixed mode takes it.
            dt = step.dt;
            attempt(dt);
        }
        // After a retry, or a step that took many iterations, the next steps start shorter and grow
        // back gradually. Where rigid objects or cloths answer inside the solve (coupling.strong),
        // the iterations count their relaxation too (5-8 a step for a box floating at rest), and
        // they are not read: shortened there, the steps jittered by a quarter at rest, the pool's
        // pressure level under a floating box rose by 0.9 r0, and the heaviest cube of the
        // extremes matrix gained energy landing (docs/solver.md, "Time step").
        const int fluid_iterations = step.pressure_response ? 0 : step.iterations;
        step_size_.after_step(state_.params.solver, step.retries, step.outcome == PcisphOutcome::kConverged, dt,
                               fluid_iterations);
        step.dt = dt;
    }

    // Symplectic Euler with the walls' correction.
    void integrate(StepContext& step) {
        ParticleStore& store = state_.store;
        integrate_fluid(state_.device, step.ranges.fluid_end, store.position.view(), store.velocity.view(),
                        step.nonpressure, pressure_acc_.cview(), state_.fluid.gravity, step.dt, walls_.walls());
    }

    bool has_viscosity() const { return has_viscosity_; }
    // Gravity plus the non-pressure forces, written by the viscosity and interface tension stages.
    View<Vec3> nonpressure() { return nonpressure_.view(); }
    // The last iteration's predicted positions and p/rho^2 (read by the coupling).
    View<const Vec3> predicted() const { return predicted_.cview(); }
    View<const Real> pressure_term() const { return pressure_term_.cview(); }
    // The last iteration's pressure acceleration, until "integrate" has used it.
    View<const Vec3> last_pressure_acceleration() const { return pressure_acc_.cview(); }
    // Two per-fluid-particle buffers free from the integration to the next step's PCISPH (the
    // predictions and the pressure accelerations): the moving solids' correction writes its
    // corrected state there before applying it.
    View<Vec3> scratch_after_integration(int which) { return which == 0 ? predicted_.view() : pressure_acc_.view(); }
    std::size_t bytes() const override {
        return nonpressure_.bytes() + pressure_acc_.bytes() + pressure_term_.bytes() + predicted_.bytes() +
               solid_met_.bytes();
    }

   private:
    // The PCISPH loop over a neighbourhood (the grid, or this step's lists), for one try of the
    // step: until the average error is below eta, and the largest below eta_max when that is set.
    // Diverged: the average error rose to more than twice the lowest it reached in this try and to
    // more than twice eta (or, with eta_max, the largest error did, against eta_max). PCISPH's
    // pressure then overshoots and feeds on itself; iterating on only throws the fluid apart, so the
    // loop stops there. The lowest may have been within the tolerance: in a 4.8 ms step of the dam
    // break at CFL 1 the peak sat at 4.7-4.9% (eta_max 5%) while the average crept down to 1.0%, then
    // the peak rose to 24% within three iterations and 154% within eight (docs/solver.md).
    template <class Rows>
    void iterate(const Rows& rows, StepContext& step, Real delta, Real dt, int& iterations) {
        const SolverParams& solver = state_.params.solver;
        const DeviceContext& device = state_.device;
        ParticleStore& store = state_.store;
        const FluidConstants<Kernel>& fluid = state_.fluid;
        const std::size_t fluid_count = step.ranges.fluid_end;
        DensityError error;
        iterations = 0;
        step.outcome = PcisphOutcome::kOutOfIterations;
        double lowest_average = 1e300, lowest_peak = 1e300;
        while (iterations < solver.max_iterations) {
            // The first prediction has no pressure acceleration yet (nothing to clear beforehand).
            const bool first = iterations == 0;
            if (step.pressure_response) step.pressure_response->before_iteration(step, dt, iterations);
            // The placement changes within a try only where objects answer inside the solve.
            if (step.lookahead.velocity && !solid_met_.empty() && (first || step.pressure_response)) {
                if (step.lookahead.end - step.lookahead.begin > solid_met_.size())
                    throw std::logic_error("PCISPH: more moving solid particles than at the start");
                place_moving_solids(device, step.lookahead, store.position.cview(), solid_met_.view().data());
                step.lookahead.met = solid_met_.view().data();
            }
            predict_positions(device, fluid_count, store.position.cview(), store.velocity.cview(), step.nonpressure,
                              first ? nullptr : pressure_acc_.view().data(), predicted_.view(), fluid.gravity, dt,
                              walls_.walls(), step.solid_surface);
            predict_density_and_pressure(device, rows, fluid_count, predicted_.cview(), store.position.cview(),
                                         step.lookahead, volumes_.volumes(), store.density.view(),
                                         store.pressure.view(), pressure_term_.view(), fluid, delta, first);
            pressure_acceleration(device, rows, fluid_count, predicted_.cview(), store.position.cview(),
                                  step.lookahead, volumes_.volumes(), pressure_term_.cview(), pressure_acc_.view(),
                                  fluid);
            ++iterations;
            // The error is a reduction read back by the host (a synchronisation on a GPU), so it is
            // computed only where it can end the loop: from the min_iterations-th iteration on. It
            // comes after the pressure force, which does not change the densities, so the force
            // kernel is already queued while the host waits.
            if (iterations < solver.min_iterations && iterations < solver.max_iterations) continue;
            error = density_error(device, fluid_count, store.density.cview(), fluid.rest_density);
            const double average = fluid_count ? error.sum / double(fluid_count) : 0.0;
            const bool peak_ok = solver.eta_max <= 0 || error.max <= solver.eta_max;
            if (average <= solver.eta && peak_ok) {
                step.outcome = PcisphOutcome::kConverged;
                break;
            }
            lowest_average = std::min(lowest_average, average);
            lowest_peak = std::min(lowest_peak, double(error.max));
            if ((average > 2 * lowest_average && average > 2 * solver.eta) ||
                (solver.eta_max > 0 && error.max > 2 * lowest_peak && error.max > 2 * solver.eta_max)) {
                step.outcome = PcisphOutcome::kDiverged;
                break;
            }
        }
        step.density_error = error;
    }

    SimulationState<Kernel>& state_;
    const BoundaryVolumes<Kernel>& volumes_;
    const WallCorrection& walls_;
    StepSizeControl& step_size_;
    bool has_viscosity_ = false;
    DeviceArray<Vec3> nonpressure_;   // gravity + viscosity + tension; only with one of them
    DeviceArray<Vec3> pressure_acc_;  // this iteration's pressure acceleration
    DeviceArray<Real> pressure_term_; // p / rho^2 of this iteration
    DeviceArray<Vec3> predicted_;     // this iteration's predicted positions
    DeviceArray<Vec3> solid_met_;     // where this iteration meets the moving solids' boundary particles (pcisph.hpp)
};

MW_BACKEND_END
