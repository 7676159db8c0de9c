// The two-way coupling module (stage "coupling", with fluid, moving solids and
// coupling.two_way): every force the fluid felt from a moving solid's boundary particles in this
// step's PCISPH goes back to the solid's inner particles (coupling.hpp), which LSM then moves.
// With coupling.strong (and predict_solids) rigid and solid elastic objects also answer the
// pressure inside PCISPH, each as one body:
// before each iteration the last one's reaction moves each object's expected acceleration
// (coupling.hpp, relax_object_accelerations), and the iteration meets the object there; a cloth's
// nodes answer one by one (relax_node_accelerations).
#pragma once
#include <cmath>
#include "algorithms/boundary_volumes.hpp"
#include "algorithms/coupling.hpp"
#include "algorithms/fluid.hpp"
#include "algorithms/melting_faces.hpp"
#include "algorithms/module.hpp"
#include "algorithms/solid_bodies.hpp"

MW_BACKEND_BEGIN

template <class Kernel>
class TwoWayCoupling final : public Module, public PressureResponse {
   public:
    TwoWayCoupling(SimulationState<Kernel>& state, const BoundaryVolumes<Kernel>& volumes, const Fluid<Kernel>& fluid,
                   SolidBodies& solids, bool lists)
        : state_(state), volumes_(volumes), fluid_(fluid), solids_(solids), lists_(lists),
          active_(state.has_fluid && solids.active() && solids.coupled()),
          strong_(active_ && (solids.has_body_answer() || solids.has_cloth()) && state.params.coupling.strong &&
                  state.params.coupling.predict_solids),
          nodal_(strong_ && solids.has_cloth()) {
        if (active_ && lists_) {
            // Room for every fluid particle of a lattice at r0 within h, and a quarter more.
            const double reach = double(state.fluid.kernel.h) / double(state.params.fluid.spacing);
            row_capacity_ = std::uint32_t(std::ceil(1.25 * 4.18879 * reach * reach * reach)) + 8;
            const CouplingData c = solids.coupling();
            const std::size_t slots = std::size_t(c.ibp_count) + c.sbp_count;
            rows_.resize(slots * row_capacity_);
            row_count_.resize(slots);
        }
        if (!strong_) return;
        const std::size_t objects = solids.object_ibps().count;
        for (DeviceArray<ObjectResponse>& r : response_) r.assign(objects, ObjectResponse{});
        relaxation_.assign(objects, ResponseRelaxation{});
        if (!nodal_) return;
        const CouplingData c = solids.coupling();
        for (DeviceArray<Vec3>& a : node_accel_) a.assign(std::size_t(c.ibp_count) + c.sbp_count, Vec3{0, 0, 0});
        for (DeviceArray<Vec3>* a : {&node_other_, &node_warm_, &node_last_velocity_, &node_target_residual_,
                                     &node_last_residual_, &node_region_acceleration_, &node_fluid_acceleration_})
            a->assign(c.ibp_count, Vec3{0, 0, 0});
    }

    void bind(StepPlan& plan) override {
        if (active_ && lists_) plan.bind("solid_volumes", [this](StepContext& step) { list_pairs(step); });
        if (strong_)
            plan.bind("solid_volumes", [this](StepContext& step) { step.pressure_response = this; });
        if (nodal_) plan.bind("solid_volumes", [this](StepContext&) { measure_nodes(); });
        if (active_) plan.bind("coupling", [this](StepContext& step) { react(step); });
    }

    // Once a step, before PCISPH: what the last step gave each cloth node apart from the fluid's
    // force (coupling.hpp, NodeResponse), and its whole acceleration, the solve's first guess.
    // Public only because nvcc allows no device lambda in a private member function.
    void measure_nodes() {
        measure_node_accelerations(state_.device, nodes(), state_.store.velocity.cview(), node_other_.view().data(),
                                   node_warm_.view().data(), node_last_velocity_.view().data(), state_.fluid.gravity,
                                   last_dt_);
    }

    // Iteration 0 (a new try): every object expected to keep its velocity; then each iteration
    // the last one's reaction relaxes the expected accelerations, into the other buffer, so that
    // the lookahead keeps the one the last iteration met (react() gathers against it).
    void before_iteration(StepContext& step, Real dt, int iteration) override {
        if (iteration == 0) {
            current_ = 0;
            start_object_responses(state_.device, response_[0].size(), response_[0].view().data(),
                                   relaxation_.view().data());
            if (nodal_) start_node_responses(state_.device, nodes(), node_warm_.view().data(), node_accel_[0].view().data());
        } else {
            const CouplingData coupling = gather(step, dt, true);
            ResponseStep response;
            response.gravity = state_.fluid.gravity;
            response.domain_min = solids_.domain_min();
            response.domain_max = solids_.domain_max();
            response.dt = dt;
            relax_object_accelerations(state_.device, solids_.object_ibps(), state_.store.position.cview(),
                                       state_.store.velocity.cview(), coupling.force, response,
                                       response_[current_].view().data(), response_[1 - current_].view().data(),
                                       relaxation_.view().data());
            if (nodal_)
                relax_node_accelerations(state_.device, nodes(), state_.store.position.cview(), state_.store.velocity.cview(),
                                         response, node_accel_[current_].view().data(),
                                         node_accel_[1 - current_].view().data());
            current_ = 1 - current_;
        }
        step.lookahead.object_response = response_[current_].view().data();
        if (nodal_) step.lookahead.slot_acceleration = node_accel_[current_].view().data();
    }

    void react(StepContext& step) {
        gather(step, step.dt, false);
        last_dt_ = step.dt;
    }

    // A cloth's nodes carry their last velocity and the last step's size into the next step.
    void save(StateArchive& out) const override {
        if (!nodal_) return;
        out.put("coupling.node_last_velocity", node_last_velocity_.to_host());
        out.put_value("coupling.node_last_dt", last_dt_);
    }
    void check(const StateArchive& in) const override {
        if (nodal_ && !in.has("coupling.node_last_velocity"))
            throw InputError("checkpoint: it holds no cloth nodes' last velocities, and this scene has a cloth under "
                             "coupling.strong; it was written for another scene");
    }
    void load(const StateArchive& in) override {
        if (!nodal_) return;
        node_last_velocity_.upload(in.get_sized<Vec3>("coupling.node_last_velocity", node_last_velocity_.size()));
        last_dt_ = in.get_value<Real>("coupling.node_last_dt");
    }

    std::size_t bytes() const override {
        return response_[0].bytes() + response_[1].bytes() + relaxation_.bytes() + rows_.bytes() +
               row_count_.bytes() + node_accel_[0].bytes() + node_accel_[1].bytes() + node_other_.bytes() +
               node_warm_.bytes() + node_last_velocity_.bytes() + node_target_residual_.bytes() +
               node_last_residual_.bytes() + node_region_acceleration_.bytes() + node_fluid_acceleration_.bytes();
    }

    // Each slot's fluid pairs for this step (lists only; coupling.hpp, list_slot_pairs).
    void list_pairs(const StepContext& step) {
        const CouplingData coupling = solids_.coupling();
        list_slot_pairs(state_.device, pairs(step), std::size_t(coupling.ibp_count) + coupling.sbp_count,
                        coupling.store_of_slot, state_.store.position.cview(), rows_.view().data(),
                        row_count_.view().data());
    }

   private:
    NodeResponse nodes() {
        NodeResponse n = solids_.node_response();
        n.other = node_other_.view().data();
        n.region_acceleration = node_region_acceleration_.view().data();
        n.fluid_acceleration = node_fluid_acceleration_.view().data();
        n.target_residual = node_target_residual_.view().data();
        n.last_residual = node_last_residual_.view().data();
        n.relaxation = relaxation_.view().data();
        return n;
    }

    FluidPairs pairs(const StepContext& step) const {
        FluidPairs pairs;
        pairs.grid = step.neighbors.grid;
        pairs.fluid_end = step.ranges.fluid_end;
        pairs.solid_end = step.ranges.solid_end;
        pairs.list_radius2 = lists_ ? state_.fluid.kernel.h * state_.fluid.kernel.h : Real(0);
        pairs.lookahead = step.lookahead;
        if (lists_) {
            pairs.rows = rows_.view().data();
            pairs.row_count = row_count_.view().data();
            pairs.row_capacity = row_capacity_;
        }
        return pairs;
    }

    // The reaction on every IBP and SBP (of the objects that answer inside PCISPH only, with
    // `answering_only`) from the fluid's last PCISPH iteration, and each IBP's force.
    CouplingData gather(const StepContext& step, Real dt, bool answering_only) {
        const FluidConstants<Kernel>& fluid = state_.fluid;
        CouplingData coupling = solids_.coupling();
        if (answering_only) {
            coupling.slot_object = solids_.slot_objects().data();
            coupling.answering_only = solids_.object_ibps().params;
        }
        coupling.inverse_dt = Real(1) / dt;
        coupling.lattice_inset = lattice_face_offset(state_.params.fluid.spacing);
        fluid_reaction_on_solids(state_.device, pairs(step), coupling, state_.store.position.cview(),
                                 state_.store.velocity.cview(), fluid_.predicted(), volumes_.volumes(),
                                 fluid_.pressure_term(), fluid, fluid_.has_viscosity() && fluid.wall_viscosity > Real(0));
        gather_solid_forces(state_.device, coupling);
        return coupling;
    }

    SimulationState<Kernel>& state_;
    const BoundaryVolumes<Kernel>& volumes_;
    const Fluid<Kernel>& fluid_;
    SolidBodies& solids_;
    bool lists_ = false;  // the fluid's pairs come from neighbour lists (their radius bounds the reaction's)
    bool active_ = false;
    bool strong_ = false;  // coupling.strong: the solids answer inside PCISPH
    bool nodal_ = false;   // ... and among them a cloth, node by node
    // Per IBP and SBP slot, the cloths' expected accelerations: the one met and the next; per IBP
    // slot, o, the first guess, the velocity at the last step's start, the residuals, and scratch.
    DeviceArray<Vec3> node_accel_[2], node_other_, node_warm_, node_last_velocity_, node_target_residual_,
        node_last_residual_, node_region_acceleration_, node_fluid_acceleration_;
    Real last_dt_ = 0;  // the last step's size (0: none yet)
    DeviceArray<ObjectResponse> response_[2];  // per object, the expected acceleration: the one met and the next
    int current_ = 0;
    DeviceArray<ResponseRelaxation> relaxation_;  // per object, Aitken's last residual and ω
    std::uint32_t row_capacity_ = 0;     // lists: each slot's row of fluid pairs, this step's
    DeviceArray<std::uint32_t> rows_, row_count_;
};

MW_BACKEND_END
