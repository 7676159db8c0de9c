// The backend-neutral face of a simulation: what apps/, tests and benchmarks see. It holds plain
// host data only (no backend types), so it can be included anywhere, CUDA or not.
#pragma once
#include <array>
#include <cstdint>
#include <memory>
#include <stdexcept>
#include <limits>
#include <string>
#include <vector>

#include "algorithms/particle_types.hpp"
#include "algorithms/sph_kernels.hpp"
#include "algorithms/state_archive.hpp"
#include "algorithms/vec3.hpp"
#include "algorithms/wall_contact.hpp"

namespace mw {

enum class TimeStepMode { kFixed, kCfl };
enum class CellOrdering { kLinear, kZOrder };

struct FluidParams {
    Real rest_density = 1000;     // ρ0, kg/m³
    Real spacing = 0.02;          // r0, m
    Real support_radius = 0.04;   // h, m
    KernelKind kernel = KernelKind::kCubicSpline;  // W for density and pressure (sph_kernels.hpp)
    Real viscosity = 0;           // μ, Pa·s (Eq. 4)
    Real wall_viscosity = 0;      // μ of fluid–wall friction, Pa·s (Eq. 8); 0: free-slip walls
    // The viscosity stage runs only when one of the two is positive.
};

struct SolverParams {
    Real dt = 0.001;                         // s: the fixed step, or the largest step in CFL mode
    TimeStepMode dt_mode = TimeStepMode::kFixed;
    Real cfl_number = 0.4;                   // CFL mode: a particle moves at most cfl · r0 a step (step_size.hpp)
    Real dt_min = 1e-6;                      // CFL mode never goes below min(this, dt)
    Real eta = 0.01;                         // PCISPH stops when the average density error < η
    Real eta_max = 0;                        // ... and, when positive, the largest one < eta_max
    int min_iterations = 3;
    int max_iterations = 100;
};

// The scenes' default peak bound: eta_max = 5 η (5% at the default η = 1%), off when that is 1 or
// more. On the default dam break it cost 1.6% more iterations and took the largest per-step error
// from 11.7% to 4.9% (31 of 1,231 steps had peaked above 5%, in the impacts on the far wall); with
// a peak bound, CFL mode also takes flat impacts without the stored compression coming back as a
// rebound (docs/solver.md, "Flat impacts"). The struct above keeps 0 so that the tests and
// benchmarks that build their parameters in code state the rule they run under.
inline double default_eta_max(double eta) {
    const double peak = 5 * eta;
    return peak < 1 ? peak : 0.0;
}

struct SimulationParams {
    Vec3 domain_min{0, 0, 0};
    Vec3 domain_max{1, 1, 1};
    // Whether the domain's faces are lined with static wall particles (the scenes' boundary.walls).
    // Then they are free-slip walls, and Eq. 4 next to them sums over the fluid's mirror images too.
    bool domain_walls = false;
    // How far outside the faces the walls' first particle layer lies (sampling/wall_gap.hpp), m;
    // negative: not given. Needed with domain_walls when wall_correction is on.
    Real wall_gap = -1;
    // The velocity–position correction against the domain walls, the static boxes and static
    // mesh objects (algorithms/wall_contact.hpp): fluid moving into them stops about r0 from the
    // walls' and boxes' first layer, 0.45 r0 from an object's surface. Off unless asked for, like
    // every physics switch added after the first release; the shipped scenes with walls ask for
    // it (boundary.correction), and so do the tests' and the benchmarks' dam breaks built in
    // code, which check what those scenes run.
    bool wall_correction = false;
    // The static boxes' faces, for that correction (their particles are in the setup's lists).
    std::vector<ContactBox> static_boxes;
    // Static mesh objects' signed distance grids, for that correction: each object's grid, its
    // values stored one object after another in static_object_distances (ContactField::field.first).
    std::vector<ContactField> static_objects;
    std::vector<Real> static_object_distances;
    // Two-way coupling (algorithms/coupling.hpp): the forces the fluid feels from a moving solid's
    // boundary particles act back on the solid. Without it solids push the fluid but feel none of
    // it (one-way, as before the eighteenth session). Off unless asked for, like the correction
    // above (the scenes' coupling.two_way).
    bool two_way_coupling = false;
    // The velocity–position correction against elastic and rigid objects' surface particles
    // (algorithms/solid_contact.hpp): fluid moving into one is stopped 0.45 r0 from its SBPs and
    // exchanges momentum with it (two-way), or takes its velocity (one-way). Off unless asked
    // for (the scenes' coupling.correction). `solid_slip`: the tangential rule's ∂ (0 no-slip,
    // 1 free slip).
    bool solid_correction = false;
    Real solid_slip = 1;
    // PCISPH solves against the moving solids' boundary particles where they will be at the end
    // of the step, not where they start it (pcisph.hpp, SolidLookahead; the scenes'
    // coupling.predict_solids). Off unless asked for, like the switches above; without it a solid
    // entering the fluid at the CFL step can blow the pool up (docs/coupling.md).
    bool solid_prediction = false;
    // Heat conduction (algorithms/heat.hpp): every fluid particle and every particle of a moving
    // solid carries a temperature (SimulationSetup::temperature) that diffuses at its material's
    // thermal diffusivity; static boundaries are adiabatic. Off unless asked for (the scenes'
    // heat.enabled): without it no temperature is stored and the stage does not run.
    struct Heat {
        bool enabled = false;
        Real fluid_diffusivity = Real(1.43e-7);  // α of the fluid, m²/s (water at 20 °C)
        Real fluid_capacity = Real(4.18e6);      // ρc of the fluid, J/(m³ K) (water)
        // Explicit sub-steps per step (heat.hpp): as many as keep every particle's update a mean
        // of its neighbours' temperatures as the scene starts, at most this.
        int max_substeps = 32;
    } heat;
    Vec3 gravity{0, -9.81f, 0};
    FluidParams fluid;
    SolverParams solver;
    CellOrdering ordering = CellOrdering::kZOrder;
    int cells_per_support = 1;  // grid cell size = h / this (1 or 2)
    // Per-step neighbour lists for the PCISPH iterations (measured 4.9x faster than grid gathers
    // on CPU cores at 100k particles; about 4 bytes per neighbour plus 16 slots of slack per fluid
    // particle), or gathering from the grid in every iteration.
    // kAuto takes the backend's preference (lists on OpenMP, grid on CUDA).
    enum class Lists { kAuto, kOn, kOff } neighbor_lists = Lists::kAuto;
};

enum class SolidKind { kElastic, kRigid, kStatic };

// One solid object (docs/lsm.md). Its particles are ordinary entries of SimulationSetup's lists
// (IBPs, SBPs and GPs, with their `object` set); the vectors below name them by their index in
// those lists and add what LSM and the interpolation need. Static objects are plain static
// boundary particles: the simulation ignores them here, apps keep their mesh for output.
struct SolidSetup {
    std::string name;
    SolidKind kind = SolidKind::kElastic;
    Real spacing = 0.02;          // lattice spacing r0 of the IBPs; IBP mass = density · r0³
    Real density = 1000;          // kg/m³
    int region_half_width = 2;    // w: a region holds the IBPs within w lattice links (elastic)
    Real stiffness = 1;           // α in (0, 1]
    Real damping = 0;             // 1/s: rate at which non-rigid velocity in each region decays
    Real wall_friction = 0.2;     // [0, 1]: share of tangential velocity removed per wall contact
    Real interface_tension = 0;   // η of Eq. 9 between its SBPs and the fluid, m⁴ kg⁻¹ s⁻² (interface_tension.hpp)
    Real thermal_diffusivity = Real(1.43e-7);  // α, m²/s, with params.heat (heat.hpp)
    Real heat_capacity = Real(4.18e6);         // ρc, J/(m³ K), with params.heat
    // Melting (melting.hpp, elastic objects with params.heat only): the object's lattice is all
    // of it (no GPs, no mesh SBPs; a lattice vertex missing one of its 26 one-ring neighbours has
    // the SBP type), and an SBP at or above the melting point that has absorbed its latent heat
    // becomes fluid. Infinite: the object never melts.
    Real melting_point = std::numeric_limits<Real>::infinity();  // °C
    Real latent_heat = 0;  // J/kg
    bool melts() const { return melting_point < std::numeric_limits<Real>::infinity(); }
    // IBPs: index in the setup's lists, integer lattice coordinates, pinned flag (empty = none).
    std::vector<std::uint32_t> ibp;
    std::vector<std::array<int, 3>> lattice;
    std::vector<std::uint8_t> pinned;
    // GPs (the vertices of the sampler's mesh: the mesh's own, in order, then the midpoints its
    // refinement added, sampling/mesh_refinement.hpp): index in the setup's lists; CSR links to IBPs (indices
    // into `ibp`) with kernel weights W(x0_g - x0_d) (Eq. 19 normalises them).
    std::vector<std::uint32_t> gp;
    std::vector<int> gp_offsets, gp_links;
    std::vector<Real> gp_weights;
    // SBPs: index in the setup's lists, the GPs of their triangle's corners, barycentric weights,
    // and the rest normal (fixes which way the deformed triangle's normal points).
    std::vector<std::uint32_t> sbp;
    std::vector<std::array<int, 3>> sbp_corners;
    std::vector<Vec3> sbp_barycentric;
    std::vector<Vec3> sbp_normal;
    // The mesh (over GP indices, outward) for output; static objects keep their vertices here.
    std::vector<std::array<int, 3>> triangles;
    std::vector<Vec3> rest_vertices;
};

// The most emitters a scene may have: each step's are passed to the release kernel by value.
constexpr std::size_t kMaxEmitters = 16;

// A fluid emitter (emitter.hpp): a disc that releases a layer of fluid particles every r0 / speed
// seconds from `start` on, `layers` layers in all. Its particles are in the setup from the start,
// of type kPending, at indices [first, first + layers * offsets.size()), layer by layer.
struct EmitterSetup {
    std::string name;
    Vec3 center{0, 0, 0};     // of the disc, m
    Vec3 direction{0, 1, 0};  // unit: the particles' velocity is speed * direction
    Real speed = 1;           // m/s
    double start = 0;         // s: the first layer leaves at start
    std::uint32_t layers = 0;
    std::vector<Vec3> offsets;  // one layer's particles relative to the centre, in the disc's plane
    std::uint32_t first = 0;    // index of its first particle in the setup's lists
    Real temperature = 20;      // °C, with params.heat
};

// Initial particles, every type in one list (the store keeps one list too).
struct SimulationSetup {
    SimulationParams params;
    std::vector<Vec3> position;
    std::vector<Vec3> velocity;
    std::vector<std::uint8_t> type;
    std::vector<std::int32_t> object;  // -1 for fluid and domain walls; static boxes, then objects
    std::vector<SolidSetup> solids;
    std::vector<EmitterSetup> emitters;
    // Initial temperature of every particle, °C (any consistent unit), with params.heat only:
    // empty otherwise.
    std::vector<Real> temperature;
};

// The particle state copied back to the host for output.
struct HostParticles {
    std::vector<Vec3> position, velocity;
    std::vector<Real> density, pressure;
    std::vector<std::uint8_t> type;
    std::vector<std::int32_t> object;
    std::vector<Real> temperature;  // empty without heat conduction
};

// A box of grid nodes for the fluid's colour field (surface_field.hpp): node (i, j, k) at
// origin + spacing (i, j, k), i fastest. sampling/lattice.hpp's LatticeGrid is the same on the
// host, in double and Eigen; this one is captured by device lambdas.
struct SurfaceNodes {
    Vec3 origin{0, 0, 0};
    Real spacing = 1;
    int dims[3] = {0, 0, 0};
    std::size_t count() const { return std::size_t(dims[0]) * std::size_t(dims[1]) * std::size_t(dims[2]); }
};

struct StepReport {
    long step = 0;
    double time = 0;           // simulated time after the step, s
    double dt = 0;             // the step just taken, s
    int iterations = 0;        // PCISPH iterations, summed over the step's tries (dt_retries)
    double density_error_avg = 0;  // average of max(ρ-ρ0,0)/ρ0 over fluid, last iteration
    double density_error_max = 0;  // maximum of the same
    double max_speed = 0;      // m/s over fluid
    double kinetic_energy = 0; // J over fluid
    long lost_particles = 0;   // fluid particles that have left the domain so far
    double solid_kinetic_energy = 0;  // J over the IBPs of moving solids
    double solid_max_speed = 0;       // m/s over the same
    int retries = 0;  // CFL mode: times this step was halved because PCISPH diverged or ran out of iterations
    bool diverged = false;  // the step's last PCISPH try still diverged (no retry left, or fixed mode)
    bool unconverged = false;  // the last try ran out of iterations above η (or eta_max), without diverging
    // The modules' own columns, in the plan's order (heat: heat_substeps and heat_content, the heat
    // Σ M T in J with T in °C; melting: melted, particles melted since the start; emitters:
    // emitted, particles emitted since the start), and their values after the step.
    std::vector<std::string> column_names;
    std::vector<double> columns;
    std::vector<double> stage_ms;  // per stage, same order as stage_names()
    double total_ms = 0;

    // The value of column `name`; throws std::out_of_range when the scene has no such column.
    double value(const std::string& name) const {
        for (std::size_t k = 0; k < column_names.size() && k < columns.size(); ++k)
            if (column_names[k] == name) return columns[k];
        throw std::out_of_range("no step report column " + name);
    }
};

struct ParticleCounts {
    std::array<long, kParticleTypeCount> by_type{};
    long total() const {
        long n = 0;
        for (long c : by_type) n += c;
        return n;
    }
};

class Simulation {
   public:
    virtual ~Simulation() = default;
    // Advances one step. Throws SimulationError naming the step and particle on NaN/inf.
    virtual void step() = 0;
    virtual const StepReport& last_report() const = 0;
    // The stages this scene runs, in the order of the method (a stage the scene does not need
    // is absent: it costs no launch and no memory).
    virtual std::vector<std::string> stage_names() const = 0;
    virtual void download(HostParticles& out) const = 0;
    // The fluid's colour field at `nodes` (surface_field.hpp), copied to the host, for surface
    // reconstruction at frame times. Rebuilds the neighbour grid from the current positions; the
    // next step's build then finds the store already in order, so a run with surfaces takes the
    // same steps, bitwise, as one without. The colour field's iso-value for the surface comes with
    // it (surface_iso_value).
    virtual void fluid_color_field(const SurfaceNodes& nodes, std::vector<Real>& color, double& iso) = 0;
    virtual ParticleCounts counts() const = 0;
    virtual std::size_t device_bytes() const = 0;
    virtual double time() const = 0;
    // Heat conduction (heat.hpp): the sub-steps a step of dt needs for every particle's update to
    // stay a mean (before the cap heat.max_substeps); 0 without heat.
    virtual int heat_substeps_needed(double dt) const = 0;
    virtual std::string backend_name() const = 0;
    virtual std::string device_name() const = 0;
    // The force the fluid exerted on each solid object in the last step, N, indexed like
    // SimulationSetup::solids (0 for static objects, and without two-way coupling). A copy to the
    // host, for tests and reports.
    virtual std::vector<std::array<double, 3>> fluid_force_on_solids() const = 0;
    // The momentum the velocity–position correction gave each solid object at the end of the last
    // step, kg m/s, which reaches its IBPs in the next step's coupling (algorithms/solid_contact.hpp);
    // 0 without the correction or two-way coupling. A copy to the host, for tests.
    virtual std::vector<std::array<double, 3>> pending_contact_impulse() const = 0;
    // Checkpoint and restart (state_archive.hpp): everything the next step reads that the scene
    // does not give, copied to the host. A simulation built from the same setup, on either
    // backend, that loads it continues as this one would, bitwise on the same backend. load_state
    // throws InputError naming what does not fit (another scene, another precision).
    virtual void save_state(StateArchive& out) const = 0;
    virtual void load_state(const StateArchive& in) = 0;
};

}  // namespace mw
