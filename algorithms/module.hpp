// The pieces every module of a simulation shares: the step context its stages hand each other,
// the plan its stages are bound into, and the lifecycle a module implements (memory, checkpoint,
// report columns). A module is one block of physics (algorithms/): it registers its store fields
// and builds its arrays in its constructor, from the scene's setup, and binds the stages it needs
// to names of algorithms/step_plan.hpp; a module the scene does not need binds nothing and holds
// no memory.
#pragma once
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "algorithms/lsm.hpp"
#include "algorithms/neighbor_grid.hpp"
#include "algorithms/neighbor_list.hpp"
#include "algorithms/pcisph.hpp"
#include "algorithms/state_archive.hpp"
#include "algorithms/virtual_boundary.hpp"
#include "algorithms/step_plan.hpp"

MW_BACKEND_BEGIN

// The neighbourhood a step's fluid gathers use, chosen once per scene: this step's lists, or the
// grid. visit() hands either to one generic function, so each gather is written once.
struct Neighborhood {
    GridView grid;
    NeighborListView lists;
    bool use_lists = false;
    template <class F>
    void visit(F&& f) const {
        if (use_lists)
            f(lists);
        else
            f(grid);
    }
};

struct StepContext;
// What answers the fluid's pressure inside the PCISPH iterations (coupling.strong,
// two_way_coupling.hpp): called before each iteration's prediction, with the previous iteration's
// predictions and pressures still in place (iteration 0: a new try of the step, at `dt`).
class PressureResponse {
   public:
    virtual void before_iteration(StepContext& step, Real dt, int iteration) = 0;

   protected:
    ~PressureResponse() = default;
};

// What one step's stages hand each other, in the order they run.
struct StepContext {
    double time = 0;     // the simulated time at the step's start, s
    Real dt = 0;         // the step; PCISPH may halve it before anything has moved
    GroupRanges ranges;  // after the sort: fluid [0, fluid_end), moving solids' boundary particles to solid_end
    Neighborhood neighbors;
    // Gravity plus viscosity and interface tension, per fluid particle, once a stage computed it;
    // null: gravity alone.
    const Vec3* nonpressure = nullptr;
    SolidSurface solid_surface;  // the moving solids' surface for their correction (inactive without it)
    SolidLookahead lookahead;    // where PCISPH meets the moving solids' boundary particles
    PressureResponse* pressure_response = nullptr;  // the solids' answer inside PCISPH (null: none)
    int iterations = 0;          // PCISPH iterations, over every try of the step
    int retries = 0;             // the step's halvings
    PcisphOutcome outcome = PcisphOutcome::kConverged;
    DensityError density_error;  // of the last iteration
    MotionSummary fluid_motion;  // after the last stage that moves the fluid
    SolidSummary solid_motion;   // after LSM
    long released = 0;           // particles emitted this step (fluid, still sorted as inactive)
};

// The stages a scene runs, in kStepStages' order: each module binds its functions by name, and a
// stage bound by several modules runs them in the order they were bound (the modules' order).
class StepPlan {
   public:
    using Function = std::function<void(StepContext&)>;
    StepPlan() : bound_(kStageCount) {}

    void bind(const char* stage, Function f) {
        const std::size_t k = stage_index(stage);
        if (k == kStageCount) throw std::logic_error(std::string("no stage named ") + stage + " in kStepStages");
        bound_[k].push_back(std::move(f));
    }
    // After every module has bound its functions: the stages to run.
    void finish() {
        stages_.clear();
        for (std::size_t k = 0; k < kStageCount; ++k)
            if (!bound_[k].empty()) stages_.push_back(k);
    }
    std::size_t size() const { return stages_.size(); }
    const char* name(std::size_t s) const { return kStepStages[stages_[s]].name; }
    void run(std::size_t s, StepContext& context) const {
        for (const Function& f : bound_[stages_[s]]) f(context);
    }

   private:
    std::vector<std::vector<Function>> bound_;  // by kStepStages index
    std::vector<std::size_t> stages_;           // the bound ones, in order
};

class Module {
   public:
    virtual ~Module() = default;
    // Binds its stage functions (none: the scene does not need it).
    virtual void bind(StepPlan& /*plan*/) {}
    // After every module exists and the first sort: buffers and reductions that the first step
    // would otherwise allocate, and set-up that needs the whole scene in place.
    virtual void start(const StepContext& /*first*/) {}
    // Bytes it holds on the device.
    virtual std::size_t bytes() const { return 0; }
    // Checkpoints (state_archive.hpp): what it carries from step to step. check() runs on every
    // module before anything loads, so that an archive that does not fit is refused whole.
    virtual void save(StateArchive& /*out*/) const {}
    virtual void check(const StateArchive& /*in*/) const {}
    virtual void load(const StateArchive& /*in*/) {}
    // Its columns of the step report (stats.csv), and their values after a step.
    virtual void report_columns(std::vector<std::string>& /*names*/) const {}
    virtual void report(std::vector<double>& /*values*/) const {}
    // The fastest speed it will give a particle after `time` that the motion summaries do not
    // see yet (an emitter's next layers), for the next CFL step.
    virtual double speed_to_come(double /*time*/) const { return 0; }
};

// What every module of one simulation reads: the device, the parameters, the particle store, the
// fluid's constants and the counts by type. One per simulation, made before its modules.
template <class Kernel>
struct SimulationState {
    SimulationState(const DeviceContext& d, const SimulationParams& p) : device(d), params(p), store(d) {}
    SimulationState(const SimulationState&) = delete;
    SimulationState& operator=(const SimulationState&) = delete;

    const DeviceContext& device;
    const SimulationParams& params;
    ParticleStore store;
    FluidConstants<Kernel> fluid;  // the kernel, rho0, the particle mass, viscosities, gravity, the walls' mirrors
    double delta_times_dt2 = 0;    // PCISPH's delta times dt^2, from the prototype lattice (pcisph_delta.hpp)
    ParticleCounts counts;         // by type; melting and emitters move particles from one to another
    bool has_fluid = false;        // fluid at the start, or fluid to come (an emitter, a melting object)
};

MW_BACKEND_END
