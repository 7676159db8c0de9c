// The size of the next step in CFL mode (host only, one per simulation): the CFL bound, which
// counts gravity's gain over the step, under a limit that PCISPH retries set and that grows back
// adaptively (docs/solver.md, "Time step").
#pragma once
#include <algorithm>
#include <cmath>

#include "simulation/simulation.hpp"
#include "algorithms/state_archive.hpp"

namespace mw {

class StepSizeControl {
   public:
    // Whether a step whose PCISPH iteration failed at `dt` (diverged, or ran out of iterations
    // above the tolerance) may be tried again at half of it (`retries` halvings so far): in CFL
    // mode only, at most 6 times, never below min(dt_min, dt).
    static bool may_retry(const SolverParams& solver, int retries, Real dt) {
        return solver.dt_mode == TimeStepMode::kCfl && retries < kMaxRetries &&
               Real(0.5) * dt >= std::min(solver.dt_min, solver.dt);
    }

    // The step to try next: in fixed mode solver.dt; in CFL mode min(limit, dt, bound), never
    // below min(dt_min, dt), where the bound is the largest Δt in which a particle at the last
    // step's top speed v (fluid or moving solid), gaining |g| Δt on the way, moves at most cfl r0:
    // (v + g Δt) Δt = cfl r0, so Δt = 2 cfl r0 / (v + √(v² + 4 g cfl r0)). Speed alone
    // (cfl r0 / v) would let a fluid at rest take the largest step, and a column falls g Δt²,
    // 2.5 r0 in 50 ms at r0 = 0.01 m: through its floor's wall in the first step.
    Real next(const SimulationParams& params, double last_max_speed) const {
        const SolverParams& solver = params.solver;
        if (solver.dt_mode == TimeStepMode::kFixed) return solver.dt;
        const Real largest = static_cast<Real>(std::min(double(solver.dt), limit_));
        const double reach = double(solver.cfl_number) * double(params.fluid.spacing);
        const double g = double(norm(params.gravity));
        const double v = last_max_speed;
        const double denominator = v + std::sqrt(v * v + 4 * g * reach);
        if (!(denominator > 0)) return largest;
        const Real cfl_dt = static_cast<Real>(2 * reach / denominator);
        // The floor never lifts the step above the scene's largest step.
        return std::max(std::min(solver.dt_min, largest), std::min(largest, cfl_dt));
    }

    // After each step's PCISPH: a step that needed retries and then held sets the limit to the
    // step that held; otherwise the limit grows by the current growth. The growth adapts to how
    // often steps fail: a retry within kWindow steps of the last halves its excess over 1 (down
    // to kGrowthLeast), and every kWindow steps without one double it back (up to kGrowthMost). A
    // resting column 20 layers deep at a largest step of 0.01 s had retried 109 of 478 steps with a
    // fixed growth of 1.25, the failed tries taking 48% of all iterations; with this, 30 retries
    // and 23% fewer iterations, while a dam break's isolated retries keep the quick growth.
    // A step whose last try failed as well (`held` false) leaves limit and growth alone: halving
    // did not rescue it, so its size was not the cause, and lowering the limit would only shrink
    // every later step (a tolerance no step size reaches would drive the step to dt_min).
    // A step that held at its first try after more than `solver.shorten_above_iterations`
    // iterations sets the limit to kShorten of itself, the growth left as it is. A solve that
    // needs many iterations meets its tolerance while the fluid gains what it does not resolve:
    // a 1 m column from rest falls freely at the top for eight steps of 5 ms that each meet η on
    // average, then no halving of the tenth converges; a collapsing column's long first steps put
    // the dam break's heights 5.7% off at r0 = a/30 (docs/solver.md, "Time step"). The caller
    // passes 0 iterations for a step in which solids answered inside the solve (their relaxation
    // counts in the iterations there).
    void after_step(const SolverParams& solver, int retries, bool held, double dt_taken, int iterations) {
        if (retries > 0 && !held) return;
        if (retries == 0 && solver.shorten_above_iterations > 0 && iterations > solver.shorten_above_iterations) {
            limit_ = kShorten * dt_taken;
            return;
        }
        if (retries > 0) {
            if (steps_since_retry_ < kWindow) growth_ = std::max(kGrowthLeast, 1 + (growth_ - 1) / 2);
            steps_since_retry_ = 0;
            limit_ = dt_taken;
        } else {
            if (++steps_since_retry_ % kWindow == 0) growth_ = std::min(kGrowthMost, 1 + (growth_ - 1) * 2);
            limit_ = std::min(1e300, limit_ * growth_);
        }
    }

    // Checkpoints: the limit and its growth shape every later step, so they travel with the state.
    void save(StateArchive& archive) const {
        archive.put_value("step_size.limit", limit_);
        archive.put_value("step_size.growth", growth_);
        archive.put_value("step_size.steps_since_retry", steps_since_retry_);
    }
    void load(const StateArchive& archive) {
        limit_ = archive.get_value<double>("step_size.limit");
        growth_ = archive.get_value<double>("step_size.growth");
        steps_since_retry_ = archive.get_value<long>("step_size.steps_since_retry");
    }

   private:
    static constexpr int kMaxRetries = 6;
    static constexpr double kGrowthMost = 1.25;
    static constexpr double kGrowthLeast = 1.01;
    static constexpr int kWindow = 20;
    static constexpr double kShorten = 0.75;
    double limit_ = 1e300;              // the largest step after a retry (grows back)
    double growth_ = kGrowthMost;
    long steps_since_retry_ = kWindow;  // no retry yet
};

}  // namespace mw
