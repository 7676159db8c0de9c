// A column of water at rest (docs/method.md: p(y) = ρ0 g (H - y)).
//
// What is asserted, and why: PCISPH's per-particle pressure is δ times the step's accumulated
// density correction, so besides the hydrostatic part it carries a particle-to-particle scatter
// (measured here: about 10% of ρ0 g H raw, about 2% after SPH smoothing). The pressure *field*
// is what the method gets right, so the test checks the interior depth profile: the SPH-smoothed
// pressure, averaged per layer of thickness r0 and over the last 0.2 s (100 steps), against
// ρ0 g (H - y), with H the settled column height. It also checks the mean density error: the solver's own figure
// against η, and an independent one, recomputed from the downloaded positions (fluid sum with the
// kernel and mass, walls with Akinci volumes computed here), against 1.5 η.
#include <doctest/doctest.h>

#include <algorithm>
#include <vector>

#include "algorithms/sph_kernels.hpp"
#include "simulation/factory.hpp"
#include "test_setups.hpp"

using namespace mw;

namespace {
// Mean compression Σ max(ρ_i - ρ0, 0) / ρ0 / N over the fluid, with ρ_i recomputed from positions:
// m Σ_j W(x_ij) over fluid j (i included) + ρ0 Σ_b V_b W(x_ib) over walls, V_b = 1 / Σ_b' W(x_bb').
double recomputed_mean_compression(const std::vector<Vec3>& fluid, const std::vector<Vec3>& walls,
                                   const CubicSpline3D& kernel, double mass, double rest_density) {
    const test::PointBins fluid_bins(fluid, kernel.h), wall_bins(walls, kernel.h);
    const std::vector<double> wall_volume = test::akinci_volumes(walls, wall_bins, kernel);
    double compression = 0;
    for (const Vec3& x : fluid) {
        double fluid_sum = 0, wall_sum = 0;
        fluid_bins.for_each_within(x, [&](std::uint32_t, double r) { fluid_sum += kernel.W(Real(r)); });
        wall_bins.for_each_within(x, [&](std::uint32_t b, double r) { wall_sum += wall_volume[b] * kernel.W(Real(r)); });
        const double rho = mass * fluid_sum + rest_density * wall_sum;
        compression += std::max(rho - rest_density, 0.0) / rest_density;
    }
    return compression / double(fluid.size());
}
}  // namespace

TEST_CASE("hydrostatic column settles to the analytic pressure profile") {
    const Real r0 = 0.02f, height = 0.5f, width = 0.2f;
    SimulationSetup setup =
        test::fluid_in_box({0, 0, 0}, {width, 0.7f, width}, {0, 0, 0}, {width, height, width}, r0, 0.002f);
    setup.params.fluid.viscosity = 0.05f;  // damps the settling sloshing
    auto sim = create_openmp_simulation(setup, 1);  // one thread: ctest runs two programs at once on 2 cores
    // 1.8 s, averaged over the last 0.2 s. Settled for 1.2 s and averaged over 0.1 s, the column
    // still sloshed (kinetic energy 0.02 J, particles at up to 0.2 m/s) and the worst layer's
    // figure depended on the phase: 0.9-2.8% over eight small changes of the set-up (μ ± 0.2%,
    // grid gathers instead of lists, the walls' mirror images on or off). Now 0.47-1.10% over the
    // same eight, in float and in double (measured this VM).
    const int steps = 900, averaged = 100;
    const CubicSpline3D kernel = CubicSpline3D::with_support(2 * r0);
    const double rest_density = setup.params.fluid.rest_density;
    const double mass = test::lattice_mass(kernel, r0, rest_density);
    double worst_recomputed = 0;
    int most_iterations = 0, diverged_steps = 0;
    std::vector<Vec3> fluid, walls;
    const test::SettledColumn column = test::settle_column(
        *sim, setup.params, steps, averaged, 0, width, 0,
        [&](int, const StepReport& report, const HostParticles* p) {
            most_iterations = std::max(most_iterations, report.iterations);
            diverged_steps += report.diverged;  // a diverged step also stops early
            if (!p) return;                     // downloaded on the averaged steps only
            fluid.clear();
            walls.clear();
            for (std::size_t i = 0; i < p->position.size(); ++i) {
                if (p->type[i] == kFluid) fluid.push_back(p->position[i]);
                if (p->type[i] == kStaticBoundary) walls.push_back(p->position[i]);
            }
            worst_recomputed =
                std::max(worst_recomputed, recomputed_mean_compression(fluid, walls, kernel, mass, rest_density));
        });
    const double worst_avg_error = column.worst_avg_error;
    // The stop rule was met on every step (a step that runs out of iterations ends with whatever
    // error it has), so the reported average error below means something.
    CHECK(most_iterations < setup.params.solver.max_iterations);
    CHECK(diverged_steps == 0);
    CHECK(worst_avg_error < setup.params.solver.eta);
    // The same error recomputed here from the positions after the step. The solver's figure is the
    // predicted density of its last iteration; the final positions carry one more pressure
    // correction, and its neighbour lists hold the pairs within h at the start of the step, so the
    // two may differ by small amounts: 1.5 η leaves room for that, and a column that was never held
    // to η (or a wrong mass or wall volume, which shift every density) fails. Measured: 0.80% both.
    CHECK(worst_recomputed < 1.5 * setup.params.solver.eta);

    const double H = column.H;
    // The column neither collapsed nor rose: 3% relative (scale 0; measured 1.8% lower, the
    // compression that holds it up).
    CHECK(H == doctest::Approx(height).epsilon(0.03).scale(0));

    const test::HydrostaticProfile& profile = column.profile;
    REQUIRE(profile.layers >= 10);
    const double worst_layer = profile.worst_layer, worst_particle = profile.worst_particle;
    MESSAGE("settled H " << H << " m; worst layer deviation " << 100 * worst_layer << "% of rho0 g H ("
                         << 100 * column.by_weight.worst_layer << "% against the weight above); worst smoothed particle "
                         << 100 * worst_particle
                         << "%; mean density error " << 100 * worst_avg_error << "% (recomputed "
                         << 100 * worst_recomputed << "%); most iterations " << most_iterations);
    CHECK(worst_layer < 0.02);
    CHECK(worst_particle < 0.05);
}

// The paper's kernel width, h = 2.5 r0 (its Table 1: r0 0.02 m, h 0.05 m). With the domain
// walls' first layer at a fixed 0.6 r0 outside the faces, which is right for h = 2 r0 only, the
// fluid next to a face starts 9% over rest density at 2.5 r0, and this column diverges in its
// first step and loses 1,507 of its 2,000 particles within 1 s, at Δt = 1 ms as at 0.5 ms. The
// walls are placed for the kernel (sampling/wall_gap.hpp).
// (At Δt = 2 ms with the scenes' peak bound eta_max = 0.05, which this set-up does not use,
// PCISPH's iteration still diverges at this width after 15-18 steps: the wider kernel lowers the
// step PCISPH holds; docs/solver.md.)
TEST_CASE("hydrostatic column at the paper's support radius h = 2.5 r0 stays at rest") {
    // 0.28 m wide: the profile leaves out 2 h along every wall, 0.1 m here.
    const Real r0 = 0.02f, height = 0.4f, width = 0.28f;
    SimulationSetup setup = test::fluid_in_box({0, 0, 0}, {width, 0.6f, width}, {0, 0, 0}, {width, height, width}, r0,
                                               0.001f, true, 2.5f);
    setup.params.fluid.viscosity = 0.05f;
    auto sim = create_openmp_simulation(setup, 1);
    const int steps = 700, averaged = 100;  // 0.7 s, averaged over the last 0.1 s
    long lost = 0;
    int diverged_steps = 0;
    const test::SettledColumn column =
        test::settle_column(*sim, setup.params, steps, averaged, 0, width, 0,
                            [&](int, const StepReport& report, const HostParticles*) {
                                diverged_steps += report.diverged;
                                lost = std::max(lost, report.lost_particles);
                            });
    MESSAGE("h = 2.5 r0: settled H " << column.H << " m; worst layer " << 100 * column.profile.worst_layer
                                     << "% of rho0 g H; mean density error " << 100 * column.worst_avg_error
                                     << "%; diverged steps " << diverged_steps << ", lost " << lost);
    CHECK(diverged_steps == 0);
    CHECK(lost == 0);
    CHECK(column.worst_avg_error < setup.params.solver.eta);
    CHECK(column.H == doctest::Approx(height).epsilon(0.03).scale(0));
    REQUIRE(column.profile.layers >= 8);
    CHECK(column.profile.worst_layer < 0.03);
}

// The same column in 2D (docs/method.md's profile is the same in a plane): the kernels normalised
// in 2D, the walls a line of particles on each of the four faces, masses per unit depth. CFL
// steps up to 2 ms, as the scenes run: at a fixed 2 ms from rest the first steps' fall is more
// than PCISPH holds (the 2D column diverged at step 20; a 3D column 0.4 x 0.1 m in plan did the
// same at step 40).
TEST_CASE("2D hydrostatic column settles to the analytic pressure profile") {
    const Real r0 = 0.02f, height = 0.5f, width = 0.4f;
    SimulationSetup setup = test::fluid_in_box({0, 0, 0}, {width, 0.7f, 0}, {0, 0, 0}, {width, height, 0}, r0, 0.002f,
                                               true, 2, KernelKind::kCubicSpline, 2);
    setup.params.fluid.viscosity = 0.05f;
    setup.params.solver.dt_mode = TimeStepMode::kCfl;
    setup.params.solver.eta_max = Real(default_eta_max(setup.params.solver.eta));
    auto sim = create_openmp_simulation(setup, 1);
    const int steps = 900, averaged = 100;
    int most_iterations = 0, diverged_steps = 0;
    double largest_z = 0;
    const test::SettledColumn column =
        test::settle_column(*sim, setup.params, steps, averaged, 0, width, 0,
                            [&](int, const StepReport& report, const HostParticles* p) {
                                most_iterations = std::max(most_iterations, report.iterations);
                                diverged_steps += report.diverged;
                                if (!p) return;
                                for (const Vec3& x : p->position) largest_z = std::max(largest_z, std::fabs(double(x.z)));
                            });
    MESSAGE("2D: settled H " << column.H << " m; worst layer " << 100 * column.by_weight.worst_layer
                             << "% of the bottom's pressure against the weight above, " << 100 * column.profile.worst_layer
                             << "% against rho0 g (H - y); worst smoothed particle " << 100 * column.by_weight.worst_particle
                             << "%; mean density error " << 100 * column.worst_avg_error << "%; most iterations "
                             << most_iterations);
    CHECK(largest_z == 0);  // the plane holds every particle exactly
    CHECK(diverged_steps == 0);
    CHECK(most_iterations < setup.params.solver.max_iterations);
    CHECK(column.worst_avg_error < setup.params.solver.eta);
    CHECK(column.H == doctest::Approx(height).epsilon(0.03).scale(0));
    // Against the weight above (static equilibrium): PCISPH leaves the column compressed by up to
    // η, and a compressed column stands lower, so ρ0 g (H - y) falls short of its weight by about
    // η ρ0 g H at the bottom (measured: 1.1% against the weight, 2.1% against ρ0 g (H - y); with
    // η = 0.5%, 1.5% against ρ0 g (H - y)). One particle's smoothed pressure scatters more than in
    // 3D: the smoothing averages over about 12 neighbours, not 33 (measured 5.6%, 3D 1.8%).
    REQUIRE(column.by_weight.layers >= 10);
    CHECK(column.by_weight.worst_layer < 0.02);
    CHECK(column.by_weight.worst_particle < 0.10);
}
