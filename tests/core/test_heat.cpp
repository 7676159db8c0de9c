// Heat conduction (algorithms/heat.hpp) in the full solver, against docs/method.md's analytic case:
// two half-spaces at T1 and T2 brought into contact at t = 0 follow
//   T(x, t) = (T1 + T2)/2 + (T2 - T1)/2 erf((x - x0) / (2 sqrt(α t))).
//
// Measured with the probe below (the project's 2-core Intel Xeon VM, OpenMP, float):
// a fluid bar 60 x 9 x 9 r0 (r0 = 0.02 m, h = 2 r0, α = 0.02 m²/s) to t = 0.32 s (sqrt(α t) = 4 r0),
// the particles within r0 of its axis against the profile. "rate": the fitted α over the true α
// (run_contact); "worst": the largest error over T2 - T1.
//
//   Fourier α Δt/r0²   sub-steps (automatic)   rate    worst   capped at 1 sub-step: rate / worst
//   0.05               1                       0.991   0.09%   (the same)
//   0.2                1                       0.998   0.03%   (the same)
//   0.5                3                       0.997   0.04%   0.475 / 9.0%
//   1                  5                       0.998   0.03%   0.235 / 16.8%
//   2                  9                       0.999   0.03%   0.116 / 23.5%
//
// The heat content moved by at most 6.2e-7 (relative) from the first step to the last, and every
// temperature stayed within [T1, T2]. Backward Euler by Jacobi sweeps (docs/method.md's scheme, built
// first) needed 4 sweeps at 0.2 and 28 at 2 and was still 4-11% slow (docs/heat.md).
#include <doctest/doctest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "../skip.hpp"
#include "simulation/factory.hpp"
#include "test_setups.hpp"

using namespace mw;

namespace {

constexpr Real kR0 = 0.02;
constexpr double kCold = 0, kHot = 100;

// A bar of fluid 60 r0 long (x) and 9 r0 square (in 2D: a strip 9 r0 wide), at rest with no
// gravity in an open domain: the half x < x0 at kCold, the rest at kHot.
struct Bar {
    SimulationSetup setup;
    double x0 = 0;
};
Bar contact_bar(double diffusivity, double dt, int max_substeps, int dimensions) {
    Bar bar;
    const Vec3 lo{0, 0, 0}, hi{Real(60 * kR0), Real(9 * kR0), Real(9 * kR0)};
    bar.setup = test::fluid_in_box(Vec3{-0.1f, -0.1f, -0.1f}, hi + Vec3{0.1f, 0.1f, 0.1f}, lo, hi, kR0, Real(dt), false,
                                   2, KernelKind::kCubicSpline, dimensions);
    bar.setup.params.gravity = Vec3{0, 0, 0};
    bar.setup.params.heat.enabled = true;
    bar.setup.params.heat.fluid_diffusivity = Real(diffusivity);
    if (max_substeps > 0) bar.setup.params.heat.max_substeps = max_substeps;  // 0: the default
    bar.x0 = 0.5 * double(hi.x);
    for (const Vec3& x : bar.setup.position) bar.setup.temperature.push_back(Real(double(x.x) < bar.x0 ? kCold : kHot));
    return bar;
}

double analytic(double x, double x0, double diffusivity, double t) {
    return 0.5 * (kCold + kHot) + 0.5 * (kHot - kCold) * std::erf((x - x0) / (2 * std::sqrt(diffusivity * t)));
}

struct ContactResult {
    double worst = 0;        // largest |T - analytic| over the bar's central column, / (T2 - T1)
    double rate_ratio = 0;   // the fitted profile's α over the true one
    double heat_drift = 0;   // |H - H(first step)| / |H(first step)|, H the heat content Σ V ρc T
    double lowest = 0, highest = 0;
    int substeps = 0;        // of the last step
};

// The least-squares slope through (x0, (T1 + T2)/2) of temperatures at offsets d from x0.
double slope_through_middle(const std::vector<double>& d, const std::vector<double>& temperature) {
    double num = 0, den = 0;
    for (std::size_t k = 0; k < d.size(); ++k) {
        num += d[k] * (temperature[k] - 0.5 * (kCold + kHot));
        den += d[k] * d[k];
    }
    return num / den;
}

// Runs the bar to `time` at Fourier number α Δt / r0² = fourier, and compares the particles within
// one r0 of the bar's axis with the analytic profile. The fitted α: the one whose analytic profile,
// sampled at the same particles within 1.6 r0 of x0, has the same least-squares slope there as the
// run's (the slope of a straight fit through erf's curve is not erf's slope at x0: taken as that,
// an exact profile would read 2% fast).
ContactResult run_contact(double fourier, int max_substeps, double time, int dimensions = 3) {
    const double diffusivity = 0.02;  // m²/s: reaches sqrt(α t) = 4 r0 in 0.32 s
    const double dt = fourier * double(kR0) * kR0 / diffusivity;
    const int steps = int(std::lround(time / dt));
    Bar bar = contact_bar(diffusivity, dt, max_substeps, dimensions);
    const double axis_z = dimensions == 2 ? 0.0 : 4.5 * kR0;  // a 2D bar is the plane z = 0
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(bar.setup, 0);
    sim->step();
    const double first_content = sim->last_report().value("heat_content");
    const HostParticles p = test::run_steps(*sim, steps - 1);
    const double t = sim->time();
    ContactResult r;
    r.substeps = sim->last_report().value("heat_substeps");
    r.heat_drift = std::fabs(sim->last_report().value("heat_content") - first_content) / std::fabs(first_content);
    std::vector<double> near_d, near_temperature;
    r.lowest = 1e30;
    r.highest = -1e30;
    for (std::size_t i = 0; i < p.position.size(); ++i) {
        if (p.type[i] != kFluid) continue;
        r.lowest = std::min(r.lowest, double(p.temperature[i]));
        r.highest = std::max(r.highest, double(p.temperature[i]));
        const Vec3 x = p.position[i];
        if (std::fabs(double(x.y) - 4.5 * kR0) > 1.01 * kR0 || std::fabs(double(x.z) - axis_z) > 1.01 * kR0) continue;
        const double error = std::fabs(double(p.temperature[i]) - analytic(double(x.x), bar.x0, diffusivity, t));
        r.worst = std::max(r.worst, error / (kHot - kCold));
        const double d = double(x.x) - bar.x0;
        if (std::fabs(d) < 1.6 * kR0) {
            near_d.push_back(d);
            near_temperature.push_back(double(p.temperature[i]));
        }
    }
    const double measured = slope_through_middle(near_d, near_temperature);
    // The analytic profile's fitted slope falls as α grows: bisect for the α that matches.
    auto fitted_slope = [&](double alpha) {
        std::vector<double> profile;
        for (double d : near_d) profile.push_back(analytic(bar.x0 + d, bar.x0, alpha, t));
        return slope_through_middle(near_d, profile);
    };
    double lo = diffusivity / 100, hi = diffusivity * 100;
    for (int k = 0; k < 100; ++k) {
        const double mid = std::sqrt(lo * hi);
        (fitted_slope(mid) > measured ? lo : hi) = mid;
    }
    r.rate_ratio = std::sqrt(lo * hi) / diffusivity;
    return r;
}

// Sums a particle list's temperatures by type.
struct TemperatureRange {
    double lowest = 1e30, highest = -1e30, sum = 0;
    long count = 0, non_finite = 0;
    void add(double t) {
        non_finite += std::isfinite(t) ? 0 : 1;
        lowest = std::min(lowest, t);
        highest = std::max(highest, t);
        sum += t;
        ++count;
    }
    double mean() const { return sum / double(count); }
};

// A rigid box 0.12 m wide at `box_temperature` in a walled pool of fluid at `fluid_temperature`,
// with no gravity: heat crosses between the fluid and the box's surface and inner particles. The
// box's heat capacity per volume is `box_capacity` times the fluid's.
SimulationSetup hot_box_in_pool(double fluid_temperature, double box_temperature, double box_capacity = 1) {
    const Vec3 lo{0, 0, 0}, hi{0.4f, 0.3f, 0.3f};
    SimulationSetup setup = test::fluid_in_box(lo, hi, lo, hi, kR0, Real(0.002));
    setup.params.gravity = Vec3{0, 0, 0};
    setup.params.heat.enabled = true;
    setup.params.heat.fluid_diffusivity = Real(0.004);
    SolidSetup solid;
    solid.name = "box";
    solid.kind = SolidKind::kRigid;
    solid.density = 1000;
    solid.thermal_diffusivity = Real(0.01);
    solid.heat_capacity = Real(box_capacity * double(setup.params.heat.fluid_capacity));
    test::add_box_solid(setup, Vec3d(0.12, 0.12, 0.12), Vec3d(0.2, 0.15, 0.15), solid, Vec3{0, 0, 0});
    for (std::size_t i = 0; i < setup.position.size(); ++i)
        setup.temperature.push_back(Real(setup.object[i] >= 0 ? box_temperature : fluid_temperature));
    return setup;
}

}  // namespace

TEST_CASE("two fluid half-spaces brought into contact follow the erf profile") {
    // Fourier numbers 0.05 and 0.2: one sub-step a step; 0.3: two.
    const struct {
        double fourier;
        int substeps;
    } cases[] = {{0.05, 1}, {0.2, 1}, {0.3, 2}};
    for (const auto& c : cases) {
        const ContactResult r = run_contact(c.fourier, 0, 0.32);
        INFO("Fourier number " << c.fourier << ": worst " << r.worst << ", rate " << r.rate_ratio << ", drift "
                               << r.heat_drift);
        CHECK(r.substeps == c.substeps);
        CHECK(r.worst < 0.004);
        CHECK(r.rate_ratio == doctest::Approx(1).epsilon(0.02));
        CHECK(r.heat_drift < 1e-5);
        CHECK(r.lowest >= kCold - 1e-3);
        CHECK(r.highest <= kHot + 1e-3);
    }
}

// The same in 2D: heat's lattice factor (Brookshaw's Laplacian made exact on the prototype
// lattice) follows the kernel's dimensions.
TEST_CASE("2D: two fluid half-planes brought into contact follow the same erf profile") {
    for (const double fourier : {0.05, 0.2}) {
        const ContactResult r = run_contact(fourier, 0, 0.32, 2);
        MESSAGE("2D, Fourier number " << fourier << ": worst " << r.worst << ", rate " << r.rate_ratio << ", drift "
                                      << r.heat_drift << ", sub-steps " << r.substeps);
        CHECK(r.worst < 0.004);
        CHECK(r.rate_ratio == doctest::Approx(1).epsilon(0.02));
        CHECK(r.heat_drift < 1e-5);
        CHECK(r.lowest >= kCold - 1e-3);
        CHECK(r.highest <= kHot + 1e-3);
    }
}

TEST_CASE("at ten times the Fourier number sub-steps keep the rate, and a capped count stays bounded") {
    const ContactResult automatic = run_contact(0.5, 0, 0.32);
    const ContactResult capped = run_contact(0.5, 1, 0.32);
    CHECK(automatic.substeps == 3);
    CHECK(capped.substeps == 1);
    CHECK(automatic.rate_ratio == doctest::Approx(1).epsilon(0.02));
    CHECK(automatic.worst < 0.004);
    CHECK(automatic.heat_drift < 1e-5);
    // Past the cap the particles move to their neighbours' mean, not past it: slower, bounded.
    CHECK(capped.rate_ratio < 0.6);
    for (const ContactResult& r : {automatic, capped}) {
        CHECK(r.lowest >= kCold - 1e-3);
        CHECK(r.highest <= kHot + 1e-3);
    }
}

TEST_CASE("a uniform temperature stays uniform next to walls and a solid, and without heat nothing is stored") {
    const SimulationSetup setup = hot_box_in_pool(37, 37);
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 0);
    const std::vector<std::string> stages = sim->stage_names();
    CHECK(std::find(stages.begin(), stages.end(), "heat") != stages.end());
    const HostParticles p = test::run_steps(*sim, 10);
    REQUIRE(p.temperature.size() == p.position.size());
    TemperatureRange all;
    for (std::size_t i = 0; i < p.position.size(); ++i)
        if (p.type[i] == kFluid || p.type[i] == kSurfaceBoundary || p.type[i] == kInnerBoundary)
            all.add(double(p.temperature[i]));
    CHECK(all.non_finite == 0);
    CHECK(all.lowest == doctest::Approx(37).epsilon(1e-5));
    CHECK(all.highest == doctest::Approx(37).epsilon(1e-5));

    SimulationSetup cold = setup;
    cold.params.heat.enabled = false;
    cold.temperature.clear();
    const std::unique_ptr<Simulation> without = create_openmp_simulation(cold, 0);
    const std::vector<std::string> cold_stages = without->stage_names();
    CHECK(std::find(cold_stages.begin(), cold_stages.end(), "heat") == cold_stages.end());
    CHECK(test::run_steps(*without, 1).temperature.empty());
    CHECK(without->device_bytes() < sim->device_bytes());
}

TEST_CASE("heat flows from a hot solid into the fluid around it, within the two temperatures, and is kept") {
    const SimulationSetup setup = hot_box_in_pool(20, 80);
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 0);
    sim->step();
    const double first_content = sim->last_report().value("heat_content");
    double previous_box = 80, previous_fluid = 20;
    for (int round = 0; round < 3; ++round) {
        const HostParticles p = test::run_steps(*sim, 20);
        TemperatureRange box, fluid, all;
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            const double t = double(p.temperature[i]);
            if (p.type[i] == kFluid) fluid.add(t);
            if (p.type[i] == kSurfaceBoundary || p.type[i] == kInnerBoundary) box.add(t);
            if (p.type[i] != kStaticBoundary && p.type[i] != kGeometry) all.add(t);
        }
        INFO("round " << round << ": box mean " << box.mean() << ", fluid mean " << fluid.mean());
        CHECK(box.mean() < previous_box - 0.1);
        CHECK(fluid.mean() > previous_fluid);
        CHECK(all.non_finite == 0);
        CHECK(all.lowest >= 20 - 1e-3);
        CHECK(all.highest <= 80 + 1e-3);
        previous_box = box.mean();
        previous_fluid = fluid.mean();
        // Σ V ρc T: the walls are adiabatic, and every pair exchanges what it takes.
        CHECK(std::fabs(sim->last_report().value("heat_content") / first_content - 1) < 1e-6);
    }
    // The mesh vertices (rendering only) keep their initial temperature.
    HostParticles p;
    sim->download(p);
    for (std::size_t i = 0; i < p.position.size(); ++i)
        if (p.type[i] == kGeometry) CHECK(double(p.temperature[i]) == 80);
}

TEST_CASE("a solid with half the fluid's heat capacity cools faster and warms the fluid less, heat kept") {
    // Heat content H = Σ V ρc T: halving the box's capacity halves the heat it holds at 80 °C and
    // doubles the rate its temperature falls at for the same flux.
    struct Means {
        double box = 0, fluid = 0, drift = 0;
    };
    auto run = [](double box_capacity) {
        const std::unique_ptr<Simulation> sim = create_openmp_simulation(hot_box_in_pool(20, 80, box_capacity), 0);
        sim->step();
        const double first_content = sim->last_report().value("heat_content");
        const HostParticles p = test::run_steps(*sim, 40);
        TemperatureRange box, fluid;
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            if (p.type[i] == kFluid) fluid.add(double(p.temperature[i]));
            if (p.type[i] == kSurfaceBoundary || p.type[i] == kInnerBoundary) box.add(double(p.temperature[i]));
        }
        return Means{box.mean(), fluid.mean(), std::fabs(sim->last_report().value("heat_content") / first_content - 1)};
    };
    const Means same = run(1), half = run(0.5);
    MESSAGE("after 41 steps: box " << same.box << " against " << half.box << " at half the capacity, fluid "
                                   << same.fluid << " against " << half.fluid << "; drift " << same.drift << ", "
                                   << half.drift);
    CHECK(half.box < same.box - 1);
    CHECK(half.fluid < same.fluid);
    CHECK(half.fluid > 20);
    CHECK(same.drift < 1e-6);
    CHECK(half.drift < 1e-6);
}

TEST_CASE("two solids conduct heat to each other without any fluid") {
    // Two rigid boxes face to face, no fluid, no gravity: the surface particles facing each other
    // conduct; the boxes' inner particles carry the heat in and out. (One r0 apart they do not:
    // their surface particles sit 0.6 r0 inside the faces, 2.2 r0 apart, beyond h.)
    const Vec3 lo{0, 0, 0}, hi{0.4f, 0.3f, 0.3f};
    SimulationSetup setup = test::empty_domain(lo, hi, kR0, Real(0.002));
    setup.params.gravity = Vec3{0, 0, 0};
    setup.params.heat.enabled = true;
    SolidSetup solid;
    solid.kind = SolidKind::kRigid;
    solid.thermal_diffusivity = Real(0.01);
    solid.name = "hot";
    test::add_box_solid(setup, Vec3d(0.12, 0.12, 0.12), Vec3d(0.14, 0.15, 0.15), solid, Vec3{0, 0, 0});
    const std::size_t hot_end = setup.position.size();
    solid.name = "cold";
    test::add_box_solid(setup, Vec3d(0.12, 0.12, 0.12), Vec3d(0.26, 0.15, 0.15), solid, Vec3{0, 0, 0});
    for (std::size_t i = 0; i < setup.position.size(); ++i)
        setup.temperature.push_back(Real(setup.object[i] < 0 ? 0.0 : i < hot_end ? 60.0 : 10.0));
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 0);
    REQUIRE(sim->counts().by_type[kFluid] == 0);
    sim->step();
    const double first_content = sim->last_report().value("heat_content");
    const HostParticles p = test::run_steps(*sim, 30);
    TemperatureRange hot, cold;
    for (std::size_t i = 0; i < p.position.size(); ++i) {
        if (p.type[i] != kSurfaceBoundary && p.type[i] != kInnerBoundary) continue;
        (i < hot_end ? hot : cold).add(double(p.temperature[i]));
    }
    MESSAGE("after 31 steps: hot box mean " << hot.mean() << ", cold box mean " << cold.mean() << ", drift "
                                            << std::fabs(sim->last_report().value("heat_content") / first_content - 1));
    CHECK(hot.mean() < 59);
    CHECK(cold.mean() > 11);
    CHECK(std::min(hot.lowest, cold.lowest) >= 10 - 1e-3);
    CHECK(std::max(hot.highest, cold.highest) <= 60 + 1e-3);
    CHECK(std::fabs(sim->last_report().value("heat_content") / first_content - 1) < 1e-6);
}

TEST_CASE("temperatures are part of the saved state: a resumed run ends bitwise where the whole one does") {
    const SimulationSetup setup = hot_box_in_pool(20, 80);
    const std::unique_ptr<Simulation> whole = create_openmp_simulation(setup, 0);
    const HostParticles uninterrupted = test::run_steps(*whole, 16);
    StateArchive saved;
    {
        const std::unique_ptr<Simulation> before = create_openmp_simulation(setup, 0);
        test::run_steps(*before, 8);
        before->save_state(saved);
    }
    REQUIRE(saved.has("store.temperature"));
    const std::unique_ptr<Simulation> resumed = create_openmp_simulation(setup, 0);
    resumed->load_state(saved);
    const HostParticles after = test::run_steps(*resumed, 8);
    CHECK(after.temperature == uninterrupted.temperature);
    CHECK(test::largest_position_difference(after, uninterrupted) == 0);
}

TEST_CASE("a saved state without temperatures is refused by a scene that conducts heat, in one line") {
    SimulationSetup cold = hot_box_in_pool(20, 80);
    cold.params.heat.enabled = false;
    cold.temperature.clear();
    StateArchive saved;
    create_openmp_simulation(cold, 0)->save_state(saved);
    const std::unique_ptr<Simulation> heated = create_openmp_simulation(hot_box_in_pool(20, 80), 0);
    std::string message;
    try {
        heated->load_state(saved);
    } catch (const InputError& e) {
        message = e.what();
    }
    CHECK(message.find("no temperatures") != std::string::npos);
    CHECK(message.find("heat.enabled") != std::string::npos);
}

TEST_CASE("CUDA and OpenMP conduct heat alike") {
    if (!cuda_backend_info().available) {
        MW_SKIP(cuda_backend_info().description);
        return;
    }
    const test::OpenmpAndCuda runs = test::run_openmp_and_cuda(hot_box_in_pool(20, 80), 30);
    double worst = 0;
    for (std::size_t i = 0; i < runs.openmp.temperature.size(); ++i)
        worst = std::max(worst, std::fabs(double(runs.openmp.temperature[i]) - double(runs.cuda.temperature[i])));
    CHECK(worst < 1e-3 * 60);
    CHECK(runs.openmp_report.value("heat_substeps") == runs.cuda_report.value("heat_substeps"));
}

TEST_CASE("heat diagnostics" * doctest::skip(std::getenv("MW_HEAT_PROBE") == nullptr)) {
    for (double fourier : {0.05, 0.2, 0.5, 1.0, 2.0})
        for (int cap : {0, 1, 2, 4}) {
            const ContactResult r = run_contact(fourier, cap, 0.32);
            std::printf("Fo %.2f cap %2d (%2d substeps): worst %.4f rate %.3f drift %.2e range [%.2f, %.2f]\n", fourier, cap,
                        r.substeps, r.worst, r.rate_ratio, r.heat_drift, r.lowest, r.highest);
        }
}
