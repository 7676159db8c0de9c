// The statistics module (stage "statistics", last): the fluid's kinetic energy, top speed and
// first non-finite particle after every stage that moves it, and the moving solids' top speed and
// kinetic energy (from their LSM step) as columns of stats.csv.
#pragma once
#include <cmath>

#include "algorithms/module.hpp"
#include "algorithms/solid_bodies.hpp"

MW_BACKEND_BEGIN

template <class Kernel>
class Statistics final : public Module {
   public:
    Statistics(SimulationState<Kernel>& state, const SolidBodies& solids) : state_(state), solids_(solids.active()) {}

    void bind(StepPlan& plan) override {
        plan.bind("statistics", [this](StepContext& step) { summarize(step); });
    }
    // The reduction makes its workspace on first use: once here, before the first step.
    void start(const StepContext& first) override {
        if (state_.has_fluid) fluid_motion(first.ranges.fluid_end);
    }

    void summarize(StepContext& step) {
        if (state_.has_fluid) step.fluid_motion = fluid_motion(step.ranges.fluid_end);
        solid_ = step.solid_motion;
    }

    void report_columns(std::vector<std::string>& names) const override {
        if (!solids_) return;
        names.push_back("solid_max_speed");
        names.push_back("solid_kinetic_energy");
    }
    // The moving solids' inner particles: m/s, J.
    void report(std::vector<double>& values) const override {
        if (!solids_) return;
        values.push_back(std::sqrt(double(solid_.max_speed2)));
        values.push_back(solid_.kinetic_energy);
    }

   private:
    MotionSummary fluid_motion(std::size_t fluid_count) const {
        return summarize_motion(state_.device, fluid_count, state_.store.position.cview(),
                                state_.store.velocity.cview(), state_.fluid.mass);
    }

    SimulationState<Kernel>& state_;
    bool solids_ = false;
    SolidSummary solid_;  // the last step's
};

MW_BACKEND_END
