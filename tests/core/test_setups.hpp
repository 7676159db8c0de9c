// Small programmatic scenes for the physics tests (the JSON route is tested in tests/cli).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "simulation/simulation.hpp"
#include "algorithms/pcisph_delta.hpp"
#include "algorithms/state_archive.hpp"
#include "algorithms/sph_kernels.hpp"
#include "apps/scene_builder.hpp"
#include "backend/backend.hpp"
#include "simulation/factory.hpp"
#include "sampling/box_particles.hpp"
#include "sampling/kdtree.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling/wall_gap.hpp"

namespace mw::test {

// Host threads at one while it lives, then back to one per core (the OpenMP default). With a
// simulation made on one thread too, a test runs as fast beside another test as alone: ctest runs
// two programs at once on CI's two cores, where two teams of threads each wait on the other's.
struct OneHostThread {
    OneHostThread() { ::mw::openmp_backend::set_host_threads(1); }
    ~OneHostThread() { ::mw::openmp_backend::set_host_threads(int(std::max(1u, std::thread::hardware_concurrency()))); }
    OneHostThread(const OneHostThread&) = delete;
    OneHostThread& operator=(const OneHostThread&) = delete;
};

// A box of fluid [block_lo, block_hi] in a domain [lo, hi] lined with Akinci walls at spacing r0/2,
// the first layer rest_density_wall_gap() outside the faces (the fluid starts at rest density);
// `walls` false leaves the domain open. The kernel is `kernel` with support radius `support_in_r0` r0.
// In 2D (`dimensions` 2) the boxes are rectangles in the plane z = 0 (their z is ignored).
inline SimulationSetup fluid_in_box(Vec3 lo, Vec3 hi, Vec3 block_lo, Vec3 block_hi, Real r0, Real dt,
                                    bool walls = true, Real support_in_r0 = 2,
                                    KernelKind kernel = KernelKind::kCubicSpline, int dimensions = 3) {
    SimulationSetup setup;
    if (dimensions == 2) lo.z = hi.z = block_lo.z = block_hi.z = 0;
    setup.params.dimensions = dimensions;
    setup.params.domain_min = lo;
    setup.params.domain_max = hi;
    setup.params.fluid.spacing = r0;
    setup.params.fluid.support_radius = support_in_r0 * r0;
    setup.params.fluid.kernel = kernel;
    setup.params.fluid.rest_density = 1000;
    setup.params.solver.dt = dt;
    for (const Vec3& p : fill_box_lattice(block_lo, block_hi, r0, dimensions)) {
        setup.position.push_back(p);
        setup.type.push_back(kFluid);
    }
    setup.params.boundary.walls = walls;
    if (walls) {
        const Real gap = rest_density_wall_gap(r0, setup.params.fluid.support_radius, r0 / 2, 1, kernel, dimensions);
        setup.params.boundary.wall_gap = gap;
        setup.params.boundary.correction = true;  // as the shipped scenes run (boundary.correction)
        for (const Vec3& p : sample_container_walls(lo, hi, r0 / 2, 1, gap, dimensions)) {
            setup.position.push_back(p);
            setup.type.push_back(kStaticBoundary);
        }
    }
    setup.velocity.assign(setup.position.size(), Vec3{0, 0, 0});
    setup.object.assign(setup.position.size(), -1);
    return setup;
}

// A walled domain [lo, hi] with no fluid: fluid_in_box's walls, its one-particle block (which
// comes first) taken out again. For scenes of solids alone.
inline SimulationSetup empty_domain(Vec3 lo, Vec3 hi, Real r0, Real dt) {
    SimulationSetup setup = fluid_in_box(lo, hi, lo, Vec3{r0, r0, r0}, r0, dt);
    if (setup.type.empty() || setup.type[0] != kFluid || (setup.type.size() > 1 && setup.type[1] == kFluid))
        throw std::logic_error("empty_domain: fluid_in_box no longer starts with a one-particle block");
    setup.position.erase(setup.position.begin());
    setup.velocity.erase(setup.velocity.begin());
    setup.type.erase(setup.type.begin());
    setup.object.erase(setup.object.begin());
    return setup;
}

// Adds a box of `size` centred on `centre` as a solid object (make_box, translated there) to a setup
// of fluid_in_box: `solid` gives its name, kind, density and LSM settings; it is sampled at the
// fluid's spacing r0 and support radius, its particles start at `velocity`, and IBPs for which
// `pinned` is true stay at rest (add_solid_object). The fluid within kFluidClearance r0 of it is then
// carved away as the scene builder does (a fluid layer that close to an Akinci layer starts 55%
// over-dense). Returns the number of fluid particles carved.
inline long add_box_solid(SimulationSetup& setup, Vec3d size, Vec3d centre, const SolidSetup& solid, Vec3 velocity,
                          const std::function<bool(const Vec3&)>& pinned = nullptr) {
    TriangleMesh box = make_box(size);
    MeshTransform t;
    t.translation = centre;
    apply_transform(box, t);
    const Real r0 = setup.params.fluid.spacing;
    const std::size_t before = setup.position.size();
    const auto object_id = static_cast<std::int32_t>(setup.solids.size());
    add_solid_object(setup, box, solid, velocity, object_id, r0, setup.params.fluid.support_radius, pinned);
    const std::vector<std::uint8_t> removed = carve_fluid(setup, Real(kFluidClearance) * r0, {}, before);
    return std::count(removed.begin(), removed.end(), 1);
}

// Steps `sim` `steps` times and returns its particles.
inline HostParticles run_steps(Simulation& sim, int steps) {
    for (int s = 0; s < steps; ++s) sim.step();
    HostParticles p;
    sim.download(p);
    return p;
}

// `setup` run `first + second` steps straight through, and again as `first` steps saved to a
// state archive and `second` more from a fresh simulation that loaded it: the checkpoint tests'
// two runs, and the saved state (for tests that tamper with it).
struct SplitRun {
    HostParticles uninterrupted, resumed;
    StepReport whole_report, saved_report, resumed_report;
    ParticleCounts whole_counts, resumed_counts;
    StateArchive saved;
};
inline SplitRun run_split(const SimulationSetup& setup, int first, int second) {
    SplitRun out;
    {
        const std::unique_ptr<Simulation> whole = create_openmp_simulation(setup, 0);
        out.uninterrupted = run_steps(*whole, first + second);
        out.whole_report = whole->last_report();
        out.whole_counts = whole->counts();
    }
    {
        const std::unique_ptr<Simulation> before = create_openmp_simulation(setup, 0);
        run_steps(*before, first);
        out.saved_report = before->last_report();
        before->save_state(out.saved);
    }
    const std::unique_ptr<Simulation> resumed = create_openmp_simulation(setup, 0);
    resumed->load_state(out.saved);
    out.resumed = run_steps(*resumed, second);
    out.resumed_report = resumed->last_report();
    out.resumed_counts = resumed->counts();
    return out;
}

// `setup` run for the same number of steps on OpenMP (at the current thread count), then on CUDA:
// the particles and the last step's report of each. The caller checks cuda_backend_info().available
// first, and skips (MW_SKIP, tests/skip.hpp) where it is not.
struct OpenmpAndCuda {
    HostParticles openmp, cuda;
    StepReport openmp_report, cuda_report;
};
inline OpenmpAndCuda run_openmp_and_cuda(const SimulationSetup& setup, int steps) {
    OpenmpAndCuda out;
    {
        const std::unique_ptr<Simulation> cpu = create_openmp_simulation(setup, 0);
        out.openmp = run_steps(*cpu, steps);
        out.openmp_report = cpu->last_report();
    }
    const std::unique_ptr<Simulation> gpu = create_cuda_simulation(setup);
    out.cuda = run_steps(*gpu, steps);
    out.cuda_report = gpu->last_report();
    return out;
}

// The two ways PCISPH can gather neighbours (per-step lists, or the grid in every iteration), and
// their names for test messages: cross-backend tests run both.
constexpr NeighborParams::Lists kGatherModes[] = {NeighborParams::Lists::kOff, NeighborParams::Lists::kOn};
inline std::string gather_mode_name(NeighborParams::Lists lists) {
    return lists == NeighborParams::Lists::kOn ? "neighbour lists" : "grid gathers";
}

// The largest distance |a.position[i] - b.position[i]| between two runs of the same setup, over the
// particles whose type (in a) `include` accepts (all when it is empty).
inline double largest_position_difference(const HostParticles& a, const HostParticles& b,
                                          const std::function<bool(std::uint8_t)>& include = nullptr) {
    double worst = 0;
    for (std::size_t i = 0; i < a.position.size(); ++i)
        if (!include || include(a.type[i])) worst = std::max(worst, double(norm(a.position[i] - b.position[i])));
    return worst;
}

// The fluid particle mass the solver uses, ρ0 / Σ W over the lattice offsets within h (the loop
// reaches 2 r0 on each axis: every offset within h for h up to 3 r0; docs/solver.md), summed
// independently of the solver's own prototype_sums.
template <class Kernel>
double lattice_mass(const Kernel& kernel, double r0, double rest_density) {
    double sum = 0;
    for (int i = -2; i <= 2; ++i)
        for (int j = -2; j <= 2; ++j)
            for (int k = -2; k <= 2; ++k) sum += kernel.W(Real(r0 * std::sqrt(double(i * i + j * j + k * k))));
    return rest_density / sum;
}

// Host-side neighbour search for the tests' own recomputations, independent of the solver's grid
// (nanoflann, in double precision). for_each_within(x, f) calls f(k, r) for every point k (index
// into the vector given) at distance r = |x - points[k]| < h.
class PointBins {
   public:
    PointBins(const std::vector<Vec3>& points, double h) : h_(h) {
        points_.reserve(points.size());
        for (const Vec3& p : points) points_.emplace_back(p.x, p.y, p.z);
        tree_ = std::make_unique<PointTree>(points_);
    }
    PointBins(const PointBins&) = delete;  // the tree refers to points_ of this object
    PointBins& operator=(const PointBins&) = delete;
    template <class F>
    void for_each_within(Vec3 x, F&& f) const {
        tree_->within(Vec3d(x.x, x.y, x.z), h_, found_);
        for (const auto& [k, r2] : found_) f(k, std::sqrt(r2));  // nanoflann gives squared distances
    }

   private:
    std::vector<Vec3d> points_;
    double h_;
    std::unique_ptr<PointTree> tree_;  // refers to points_: built after it, destroyed before it
    mutable std::vector<std::pair<std::uint32_t, double>> found_;
};

// Akinci boundary volumes V_b = 1 / Σ_b' W(x_bb') over the points of `bins` (b itself included),
// recomputed on the host, independently of the solver's compute_boundary_volumes.
template <class Kernel>
std::vector<double> akinci_volumes(const std::vector<Vec3>& boundary, const PointBins& bins, const Kernel& kernel) {
    std::vector<double> volume(boundary.size());
    for (std::size_t b = 0; b < boundary.size(); ++b) {
        double sum = 0;
        bins.for_each_within(boundary[b], [&](std::uint32_t, double r) { sum += kernel.W(Real(r)); });
        volume[b] = 1 / sum;
    }
    return volume;
}

// Adds each fluid particle's SPH-smoothed pressure, Σ_j W_ij p_j/ρ_j / Σ_j W_ij/ρ_j over fluid j,
// to smoothed_sum[i] (indexed like p). PCISPH's raw per-particle pressure carries the step's
// correction impulse (a scatter of about 10% of ρ0 g H); the smoothed field is what it gets right.
template <class Kernel>
void add_smoothed_pressure(const HostParticles& p, const Kernel& kernel, std::vector<double>& smoothed_sum) {
    std::vector<Vec3> fluid;
    std::vector<std::size_t> index;  // index in p of each entry of `fluid`
    for (std::size_t i = 0; i < p.position.size(); ++i)
        if (p.type[i] == kFluid) fluid.push_back(p.position[i]), index.push_back(i);
    smoothed_sum.resize(p.position.size(), 0.0);
    const PointBins bins(fluid, kernel.h);
    for (std::size_t k = 0; k < fluid.size(); ++k) {
        double num = 0, den = 0;
        bins.for_each_within(fluid[k], [&](std::uint32_t l, double r) {
            const std::size_t j = index[l];
            const double w = kernel.W(Real(r)) / p.density[j];
            num += w * p.pressure[j];
            den += w;
        });
        smoothed_sum[index[k]] += num / den;
    }
}

// A settled column's pressure against an expected profile p(y) over [bottom, top]: the smoothed
// pressure averaged over `averaged` steps (smoothed_sum / averaged) for the fluid particles whose
// position averaged over the same steps (mean_position) is inside `interior`, as a deviation
// relative to `scale` (the expected pressure at the bottom), averaged per layer r0 thick.
struct HydrostaticProfile {
    double worst_layer = 0, worst_particle = 0;
    std::size_t layers = 0;
};
inline HydrostaticProfile hydrostatic_profile(const HostParticles& p, const std::vector<double>& smoothed_sum,
                                              const std::vector<Vec3>& mean_position, int averaged,
                                              const std::function<double(double)>& expected, double scale,
                                              double bottom, double r0, Vec3 interior_lo, Vec3 interior_hi) {
    std::map<int, std::pair<double, int>> layers;  // layer -> (sum of relative deviation, count)
    HydrostaticProfile out;
    for (std::size_t i = 0; i < p.position.size(); ++i) {
        const Vec3 x = mean_position[i];
        if (p.type[i] != kFluid || x.x < interior_lo.x || x.x > interior_hi.x || x.y < interior_lo.y ||
            x.y > interior_hi.y || x.z < interior_lo.z || x.z > interior_hi.z)
            continue;
        const double deviation = (smoothed_sum[i] / averaged - expected(x.y)) / scale;
        out.worst_particle = std::max(out.worst_particle, std::fabs(deviation));
        auto& layer = layers[int((x.y - bottom) / r0)];
        layer.first += deviation;
        ++layer.second;
    }
    for (const auto& [index, sum] : layers) out.worst_layer = std::max(out.worst_layer, std::fabs(sum.first / sum.second));
    out.layers = layers.size();
    return out;
}

// A fluid column at rest, measured as test_hydrostatic.cpp measures it: `sim` (a column `width`
// square from x = z = 0, its fluid standing on `bottom`) is stepped `steps` times; over the last
// `averaged` steps the largest reported mean density error is kept, and the smoothed pressure
// (add_smoothed_pressure), each particle's position and the column's height H (the highest fluid
// centre + r0/2) are averaged; then the hydrostatic_profile over the interior (2 h clear of the
// side walls, of `bottom` and of the surface, where the free surface and the walls' truncated
// kernel sums do not reach) against two references:
//  - ρ0 g (H - y), with H the settled height: `profile`;
//  - the weight of the fluid above y per unit area (per unit width in 2D), g m Σ_j f_j(y) / A,
//    f_j the part of particle j's cell (r0 tall, centred on its mean height) above y: `by_weight`.
//    Static equilibrium, whatever the density: the fluid PCISPH leaves compressed by up to η
//    weighs the same but stands lower, so ρ0 g (H - y) falls short of it by about η ρ0 g H at the
//    bottom.
struct SettledColumn {
    HostParticles particles;  // after the last step
    double worst_avg_error = 0, H = 0;  // H: averaged over the last steps
    HydrostaticProfile profile, by_weight;
};
// `on_step(step, report, particles)` runs after every step with its report; `particles` is the
// download made on the averaged steps, and on every `download_every`th step before them (0: none),
// and null on the other steps.
using OnSettleStep = std::function<void(int step, const StepReport& report, const HostParticles* particles)>;
inline SettledColumn settle_column(Simulation& sim, const SimulationParams& params, int steps, int averaged,
                                   double bottom, Real width, int download_every, const OnSettleStep& on_step) {
    const Real r0 = params.fluid.spacing;
    SettledColumn out;
    std::vector<double> smoothed_sum;
    std::vector<double> position_sum;  // x, y, z of each particle, summed over the averaged steps
    double top_sum = 0;
    for (int step = 0; step < steps; ++step) {
        sim.step();
        const bool in_average = step >= steps - averaged;
        const bool download = in_average || (download_every > 0 && step % download_every == 0);
        if (download) sim.download(out.particles);
        if (on_step) on_step(step, sim.last_report(), download ? &out.particles : nullptr);
        if (!in_average) continue;
        out.worst_avg_error = std::max(out.worst_avg_error, sim.last_report().density_error_avg);
        with_kernel(KernelKind::kCubicSpline, params.dimensions, params.fluid.support_radius,
                    [&](const auto& kernel) { add_smoothed_pressure(out.particles, kernel, smoothed_sum); });
        const HostParticles& p = out.particles;
        position_sum.resize(3 * p.position.size(), 0.0);
        double top = 0;
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            position_sum[3 * i] += p.position[i].x;
            position_sum[3 * i + 1] += p.position[i].y;
            position_sum[3 * i + 2] += p.position[i].z;
            if (p.type[i] == kFluid) top = std::max(top, double(p.position[i].y));
        }
        top_sum += top;
    }
    const HostParticles& p = out.particles;
    std::vector<Vec3> mean_position(p.position.size());
    for (std::size_t i = 0; i < p.position.size(); ++i)
        mean_position[i] = Vec3{Real(position_sum[3 * i] / averaged), Real(position_sum[3 * i + 1] / averaged),
                                Real(position_sum[3 * i + 2] / averaged)};
    out.H = top_sum / averaged + r0 / 2;
    const double rho_g = double(params.fluid.rest_density) * -double(params.gravity.y),
                 margin = 2 * double(params.fluid.support_radius);
    // In 2D the column is the plane z = 0.
    const Real z_lo = params.dimensions == 2 ? Real(0) : Real(margin);
    const Real z_hi = params.dimensions == 2 ? Real(0) : Real(width - margin);
    const Vec3 interior_lo{Real(margin), Real(bottom + margin), z_lo};
    const Vec3 interior_hi{Real(width - margin), Real(out.H - margin), z_hi};
    const double H = out.H;
    out.profile = hydrostatic_profile(
        p, smoothed_sum, mean_position, averaged, [&](double y) { return rho_g * (H - y); }, rho_g * (H - bottom),
        bottom, r0, interior_lo, interior_hi);
    const double mass = with_kernel(KernelKind::kCubicSpline, params.dimensions, params.fluid.support_radius,
                                    [&](const auto& kernel) {
                                        return double(params.fluid.rest_density) /
                                               prototype_sums(kernel, r0, params.dimensions).sum_W;
                                    });
    const double area = params.dimensions == 2 ? double(width) : double(width) * width;
    const auto weight_above = [&](double y) {
        double cells = 0;
        for (std::size_t j = 0; j < p.position.size(); ++j)
            if (p.type[j] == kFluid) cells += std::clamp((mean_position[j].y + r0 / 2 - y) / r0, 0.0, 1.0);
        return -double(params.gravity.y) * mass * cells / area;
    };
    out.by_weight = hydrostatic_profile(p, smoothed_sum, mean_position, averaged, weight_above, weight_above(bottom),
                                        bottom, r0, interior_lo, interior_hi);
    return out;
}

// A 0.1 m box (`kind`, `density`, stiffness 0.5, damping 2/s) thrown at (1, -2, 0) m/s from
// `drop` above a resting pool 0.24 m deep (a 0.3 x 0.24 x 0.2 m block in a 0.6 x 0.5 x 0.2 m tank,
// r0 = 0.02 m), two-way coupling, CFL steps up to 4 ms with eta_max 5%, μ = 0.01 Pa·s. Callers
// switch the correction and the lookahead in `setup.params` (the impact and checkpoint tests).
inline SimulationSetup box_thrown_onto_pool(SolidKind kind, double density, double drop) {
    const Real r0 = 0.02f;
    SimulationSetup setup = fluid_in_box({0, 0, 0}, {0.6f, 0.5f, 0.2f}, {0, 0, 0}, {0.3f, 0.24f, 0.2f}, r0, 0.004f);
    setup.params.solver.dt_mode = TimeStepMode::kCfl;
    setup.params.solver.eta_max = 0.05f;
    setup.params.fluid.viscosity = 0.01f;
    setup.params.coupling.two_way = true;
    SolidSetup solid;
    solid.name = "box";
    solid.kind = kind;
    solid.density = Real(density);
    solid.stiffness = 0.5f;
    solid.damping = 2;
    add_box_solid(setup, Vec3d(0.1, 0.1, 0.1), Vec3d(0.15, 0.24 + drop + 0.05, 0.1), solid, Vec3{1.0f, -2.0f, 0});
    return setup;
}

// A 0.12 m cube of fluid at `speed` along +x toward a free cube of solid (0.12 m, density 1000,
// `kind`, stiffness 0.5) at rest 2 r0 ahead of it, in an open domain (0.8 x 0.4 x 0.4 m) with no
// gravity, r0 = 0.02 m, steps of `dt` (the coupling's momentum tests). Callers switch the
// coupling, the correction and the gathers in `setup.params`.
struct CubeThrow {
    static constexpr Real r0 = 0.02f;
    SimulationSetup setup;
    double fluid_mass = 0, ibp_mass = 0;  // kg per fluid particle and per IBP

    // The cube as a melting object's lattice alone (heat on): kNone a mesh's object; kWhole far
    // below its melting point; kMelting at it, with the fluid's particle mass, in fluid at 20 °C,
    // so that what the fluid touches melts.
    enum class Lattice { kNone, kWhole, kMelting };
    CubeThrow(SolidKind kind, Real speed, Real dt, Lattice lattice = Lattice::kNone) {
        setup = fluid_in_box({0, 0, 0}, {0.8f, 0.4f, 0.4f}, {0.1f, 0.14f, 0.14f}, {0.22f, 0.26f, 0.26f}, r0, dt,
                             /*walls=*/false);
        setup.params.gravity = Vec3{0, 0, 0};
        for (std::size_t i = 0; i < setup.position.size(); ++i) setup.velocity[i] = Vec3{speed, 0, 0};
        SolidSetup solid;
        solid.name = "cube";
        solid.kind = kind;
        solid.density = 1000;
        solid.stiffness = 0.5f;
        fluid_mass = lattice_mass(CubicSpline3D::with_support(2 * r0), r0, 1000.0);
        if (lattice != Lattice::kNone) {
            setup.params.heat.enabled = true;
            setup.params.heat.fluid_diffusivity = Real(0.01);
            solid.thermal_diffusivity = Real(0.01);
            solid.melting_point = Real(lattice == Lattice::kWhole ? 1e4 : 0);
            solid.latent_heat = Real(lattice == Lattice::kWhole ? 1e12 : 2000);
            if (lattice == Lattice::kMelting) solid.density = Real(fluid_mass / (double(r0) * r0 * r0));
        }
        add_box_solid(setup, Vec3d(0.12, 0.12, 0.12), Vec3d(0.22 + 2 * r0 + 0.06, 0.2, 0.2), solid, Vec3{0, 0, 0});
        for (std::size_t i = 0; lattice != Lattice::kNone && i < setup.position.size(); ++i)
            setup.temperature.push_back(Real(setup.object[i] < 0 ? 20 : 0));
        ibp_mass = solid.density * double(r0) * r0 * r0;
        melting_lattice = lattice != Lattice::kNone;
    }
    // Total momentum along x of the fluid and of the IBPs (SBPs and GPs carry no mass, but a
    // melting lattice's exposed vertices, its SBPs, are IBPs that do).
    void momentum(const HostParticles& p, double& fluid, double& solid) const {
        fluid = solid = 0;
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            if (p.type[i] == kFluid) fluid += fluid_mass * p.velocity[i].x;
            if (p.type[i] == kInnerBoundary || (melting_lattice && p.type[i] == kSurfaceBoundary))
                solid += ibp_mass * p.velocity[i].x;
        }
    }
    bool melting_lattice = false;  // the cube is a melting object's lattice
};

}  // namespace mw::test
