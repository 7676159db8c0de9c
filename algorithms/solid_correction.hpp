// The moving solids' correction module (with fluid, moving solids and coupling.correction): the
// velocity-position correction against elastic and rigid objects' surface particles
// (solid_contact.hpp; the paper's section 3.3). Its position rule runs in every PCISPH prediction
// (through the step's SolidSurface), its whole rule after the integration (stage
// "solid_contact"). Two-way, the objects take the impulses, in the next step's coupling.
#pragma once
#include "algorithms/fluid.hpp"
#include "algorithms/module.hpp"
#include "algorithms/solid_bodies.hpp"
#include "algorithms/solid_contact.hpp"
#include "algorithms/wall_correction.hpp"

MW_BACKEND_BEGIN

template <class Kernel>
class SolidCorrection final : public Module {
   public:
    // Whether a scene needs it.
    static bool needed(const SimulationState<Kernel>& state, const SolidBodies& solids) {
        return state.has_fluid && solids.active() && state.params.coupling.correction;
    }

    SolidCorrection(SimulationState<Kernel>& state, Fluid<Kernel>& fluid, SolidBodies& solids,
                    const WallCorrection& walls)
        : state_(state), fluid_(fluid), solids_(solids), walls_(walls), active_(needed(state, solids)) {
        if (!(state.params.coupling.slip >= 0 && state.params.coupling.slip <= 1))
            throw InputError("simulation setup: the solids' slip factor must be in [0, 1]");
        if (!active_) return;
        const std::size_t moving = state.store.moving_count();
        band_ = static_cast<Real>(moving_solid_contact(solids.surface_inset() || solids.lattice_faces_met()) * state.params.fluid.spacing);
        near_solid_.resize(moving);
        if (solids.contact_takes_impulses()) impulse_per_weight_.resize(moving);
    }

    void bind(StepPlan& plan) override {
        if (!active_) return;
        plan.bind("neighbors", [this](StepContext& step) { find_surface(step); });
        plan.bind("solid_contact", [this](StepContext& step) { correct(step); });
    }

    // After the sort: which fluid particles have a moving solid's particle in the cells around
    // them (the correction's gathers skip the others), and the solids' surface for this step.
    void find_surface(StepContext& step) {
        mark_fluid_near_solids(state_.device, step.ranges.fluid_end, step.neighbors.grid, near_solid_.view());
        step.solid_surface = solids_.surface(state_.store, step.neighbors.grid, band_, state_.params.fluid.spacing);
        step.solid_surface.fluid_near_solid = near_solid_.view().data();
    }

    // After the integration. Two-way, each SBP gathers its share of the momentum from the fluid's
    // state before the correction, so the corrected state goes to scratch first: the PCISPH loop's
    // predictions and pressure accelerations, free until the next step's loop.
    void correct(StepContext& step) {
        ParticleStore& store = state_.store;
        const std::size_t fluid_count = step.ranges.fluid_end;
        SolidContactData contact =
            solids_.contact(step.solid_surface, state_.params.coupling.slip, state_.fluid.mass, impulse_per_weight_.view().data());
        contact.dt = step.dt;
        if (solids_.contact_takes_impulses()) {
            View<Vec3> corrected_position = fluid_.scratch_after_integration(0);
            View<Vec3> corrected_velocity = fluid_.scratch_after_integration(1);
            correct_fluid_at_solids(state_.device, fluid_count, store.position.cview(), store.velocity.cview(),
                                    corrected_position, corrected_velocity, contact, walls_.walls());
            if (contact.sbp_impulse)
                gather_sbp_impulses(state_.device, step.ranges.fluid_end, step.ranges.solid_end, store.position.cview(),
                                    contact);
            if (contact.lattice_impulse)
                gather_lattice_impulses(state_.device, step.ranges.fluid_end, step.ranges.solid_end,
                                        store.position.cview(), contact);
            apply_fluid_correction(state_.device, fluid_count, corrected_position, corrected_velocity,
                                   store.position.view(), store.velocity.view());
        } else {
            correct_fluid_at_solids(state_.device, fluid_count, store.position.cview(), store.velocity.cview(),
                                    store.position.view(), store.velocity.view(), contact, walls_.walls());
        }
    }

    bool active() const { return active_; }
    std::size_t bytes() const override { return impulse_per_weight_.bytes() + near_solid_.bytes(); }

   private:
    SimulationState<Kernel>& state_;
    Fluid<Kernel>& fluid_;
    SolidBodies& solids_;
    const WallCorrection& walls_;
    bool active_ = false;
    Real band_ = 0;                          // c, m: how far from the surface fluid is stopped
    DeviceArray<Vec3> impulse_per_weight_;   // per fluid particle (two-way only)
    DeviceArray<std::uint8_t> near_solid_;   // per fluid particle: a solid's particle in its cells
};

MW_BACKEND_END
