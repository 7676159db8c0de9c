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

#include "algorithms/boundary_params.hpp"
#include "algorithms/coupling_params.hpp"
#include "algorithms/emitter_params.hpp"
#include "algorithms/fluid_params.hpp"
#include "algorithms/heat_params.hpp"
#include "algorithms/neighbor_params.hpp"
#include "algorithms/particle_types.hpp"
#include "algorithms/pressure_sensor_params.hpp"
#include "algorithms/solid_params.hpp"
#include "algorithms/sph_kernels.hpp"
#include "algorithms/state_archive.hpp"
#include "algorithms/vec3.hpp"
#include "algorithms/wall_contact.hpp"

namespace mw {

// Every module's parameters, as the scene resolves them (apps/scene.cpp) or a test builds them.
// Each struct's member defaults are the scenes' defaults (their tables say so: `meltwater
// schema`), but for the geometry the scene builder fills in.
struct SimulationParams {
    // 3, or 2: every particle in the plane z = 0, the kernels normalised in 2D, walls on the four
    // faces normal to x and y only (the domain's z extent is [0, 0]).
    int dimensions = 3;
    Vec3 domain_min{0, 0, 0};
    Vec3 domain_max{1, 1, 1};
    Vec3 gravity{0, -9.81f, 0};
    FluidParams fluid;
    SolverParams solver;
    BoundaryParams boundary;
    CouplingParams coupling;
    HeatParams heat;
    NeighborParams neighbors;
};

// One solid object (docs/lsm.md): its parameters, and its particles. These are ordinary entries
// of SimulationSetup's lists (IBPs, SBPs and GPs, with their `object` set); the vectors below name
// them by their index in those lists and add what LSM and the interpolation need. Static objects
// are plain static boundary particles: the simulation ignores them here, apps keep their mesh for
// output.
struct SolidSetup : SolidParams {
    std::string name;
    Real spacing = 0.02;  // lattice spacing r0 of the IBPs; IBP mass = density r0^3
    // IBPs: index in the setup's lists, integer lattice coordinates, pinned flag (empty = none).
    std::vector<std::uint32_t> ibp;
    std::vector<std::array<int, 3>> lattice;
    std::vector<std::uint8_t> pinned;
    // Each IBP's mass (empty: density r0^3, a lattice cell's), and the graph its regions grow on
    // when it has no lattice (cloth: the mesh's edges; CSR over indices into `ibp`).
    std::vector<Real> ibp_mass;
    std::vector<std::uint32_t> ibp_graph_offsets, ibp_graph_links;
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
    // How far each SBP sits inside the face along its normal (m; empty: on it), where the fluid
    // meets the face point x_s + inset n_s (sampling/surface_inset.hpp).
    std::vector<Real> sbp_inset;
    // The mesh (over GP indices, outward) for output; static objects keep their vertices here.
    std::vector<std::array<int, 3>> triangles;
    std::vector<Vec3> rest_vertices;
};

// The most emitters a scene may have: each step's are passed to the release kernel by value.
constexpr std::size_t kMaxEmitters = 16;

// A fluid emitter (emitter.hpp): a disc that releases a layer of fluid particles every r0 / speed
// seconds from `start` on, `layers` layers in all. Its particles are in the setup from the start,
// of type kPending, at indices [first, first + layers * offsets.size()), layer by layer.
struct EmitterSetup : EmitterParams {
    std::string name;
    std::uint32_t layers = 0;
    std::vector<Vec3> offsets;  // one layer's particles relative to the centre, in the disc's plane
    std::uint32_t first = 0;    // index of its first particle in the setup's lists
};

// A pressure sensor (pressure_sensors.hpp): a square patch of the domain's face normal to `axis`,
// its low face (side -1) or its high face (side +1).
struct PressureSensorSetup : PressureSensorParams {
    std::string name;
    int axis = 0;
    int side = -1;
};

// Initial particles, every type in one list (the store keeps one list too).
struct SimulationSetup {
    SimulationParams params;
    std::vector<Vec3> position;
    std::vector<Vec3> velocity;
    std::vector<std::uint8_t> type;
    // Each particle's body: its index in `solids` (the scene's objects, then its static boxes); -1
    // for fluid and the domain walls.
    std::vector<std::int32_t> object;
    std::vector<SolidSetup> solids;
    std::vector<EmitterSetup> emitters;
    std::vector<PressureSensorSetup> pressure_sensors;
    // Initial temperature of every particle, °C (any consistent unit), with params.heat only:
    // empty otherwise.
    std::vector<Real> temperature;

    // Whether the scene holds fluid or will: fluid particles, an emitter's pending ones, or an
    // object that melts.
    bool has_fluid() const {
        for (std::uint8_t t : type)
            if (t == kFluid || t == kPending) return true;
        if (!emitters.empty()) return true;
        for (const SolidSetup& s : solids)
            if (s.melts()) return true;
        return false;
    }
    // Whether moving objects stop a fluid layer short of the walls and static boxes
    // (coupling.wall_film, in a scene with fluid; algorithms/lsm_regions.hpp, object_keeps_wall_film).
    bool keeps_wall_film() const { return params.coupling.wall_film && has_fluid(); }

    // Whether any moving object's SBP sits inside its face (SolidSetup::sbp_inset): the
    // correction's band is then the narrower one (algorithms/wall_contact.hpp).
    bool any_sbp_set_in() const {
        for (const SolidSetup& s : solids)
            for (Real inset : s.sbp_inset)
                if (inset > Real(0)) return true;
        return false;
    }
    // Whether the correction meets the moving objects with the narrower band: an SBP set in, or a
    // melting object, whose faces lie half a spacing in front of its vertices
    // (algorithms/melting_faces.hpp).
    bool narrow_solid_band() const {
        for (const SolidSetup& s : solids)
            if (s.melts()) return true;
        return any_sbp_set_in();
    }
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

    bool has(const std::string& name) const {
        for (const std::string& c : column_names)
            if (c == name) return true;
        return false;
    }
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
