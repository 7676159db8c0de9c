// The two-way coupling module (stage "coupling", with fluid, moving solids and
// coupling.two_way): every force the fluid felt from a moving solid's boundary particles in this
// step's PCISPH goes back to the solid's inner particles (coupling.hpp), which LSM then moves.
#pragma once
#include "algorithms/boundary_volumes.hpp"
#include "algorithms/coupling.hpp"
#include "algorithms/fluid.hpp"
#include "algorithms/module.hpp"
#include "algorithms/solid_bodies.hpp"

MW_BACKEND_BEGIN

template <class Kernel>
class TwoWayCoupling final : public Module {
   public:
    TwoWayCoupling(SimulationState<Kernel>& state, const BoundaryVolumes<Kernel>& volumes, const Fluid<Kernel>& fluid,
                   SolidBodies& solids, bool lists)
        : state_(state), volumes_(volumes), fluid_(fluid), solids_(solids), lists_(lists),
          active_(state.has_fluid && solids.active() && solids.coupled()) {}

    void bind(StepPlan& plan) override {
        if (active_) plan.bind("coupling", [this](StepContext& step) { react(step); });
    }

    void react(StepContext& step) {
        const FluidConstants<Kernel>& fluid = state_.fluid;
        CouplingData coupling = solids_.coupling();
        FluidPairs pairs;
        pairs.grid = step.neighbors.grid;
        pairs.fluid_end = step.ranges.fluid_end;
        pairs.solid_end = step.ranges.solid_end;
        pairs.list_radius2 = lists_ ? fluid.kernel.h * fluid.kernel.h : Real(0);
        pairs.lookahead = step.lookahead;
        coupling.inverse_dt = Real(1) / step.dt;
        fluid_reaction_on_solids(state_.device, pairs, coupling, state_.store.position.cview(),
                                 state_.store.velocity.cview(), fluid_.predicted(), volumes_.volumes(),
                                 fluid_.pressure_term(), fluid, fluid_.has_viscosity() && fluid.wall_viscosity > Real(0));
        gather_solid_forces(state_.device, coupling);
    }

   private:
    SimulationState<Kernel>& state_;
    const BoundaryVolumes<Kernel>& volumes_;
    const Fluid<Kernel>& fluid_;
    SolidBodies& solids_;
    bool lists_ = false;  // the fluid's pairs come from neighbour lists (their radius bounds the reaction's)
    bool active_ = false;
};

MW_BACKEND_END
