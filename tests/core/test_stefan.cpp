// Melting against the one-phase Stefan problem (docs/method.md): a solid at its melting point T_m
// meets a wall held at T_w > T_m. The liquid between them conducts; the solid does not warm. The
// front advances as s(t) = 2 λ sqrt(α t), with λ e^{λ²} erf(λ) = St / sqrt(π) and the Stefan
// number St = C_l (T_w − T_m) / (ρ_s L), α and C_l the liquid's diffusivity and heat capacity per
// volume, ρ_s L the latent heat per volume.
//
// The setup: no gravity, the domain's walls far away. A slab of melting solid (a lattice) lies
// along x, one lattice spacing from a plate held at T_w: a pinned object whose heat capacity is 10⁶
// times the liquid's, so that it gives heat without cooling, and whose melting point (10⁴ °C, never
// reached) makes it a lattice like the slab's. What melts is liquid between the plate and the
// front. The solid has the liquid's density and heat capacity, so the melted volume is the solid's
// and St reads the latent store in kelvins: St = (T_w − T_m) / (L ρ / C). The front is the count of
// lattice layers melted in the slab's central columns, away from its free sides. Figures:
// docs/validation.md, "Melting".
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include "simulation/factory.hpp"
#include "test_setups.hpp"

using namespace mw;

namespace {

constexpr Real kR0 = 0.02;
constexpr double kWall = 10, kMelt = 0;     // °C
constexpr double kDiffusivity = 0.08;       // m²/s: the liquid's and the solid's
constexpr double kCapacity = 4.18e6;        // J/(m³ K): the liquid's and the solid's
constexpr double kDensity = 1000;           // kg/m³: the liquid's rest density and the solid's


// λ of the one-phase Stefan problem: the root of λ e^{λ²} erf(λ) = St / sqrt(π) (increasing in λ).
double stefan_lambda(double stefan) {
    const double target = stefan / std::sqrt(M_PI);
    double lo = 0, hi = 3;
    for (int k = 0; k < 200; ++k) {
        const double mid = 0.5 * (lo + hi);
        (mid * std::exp(mid * mid) * std::erf(mid) < target ? lo : hi) = mid;
    }
    return 0.5 * (lo + hi);
}

struct StefanRun {
    double lambda = 0;    // fitted to the front's crossings of whole layers
    double analytic = 0;  // λ of the Stefan number
    int layers = 0;       // layers melted in the central columns at the end
    double time = 0;
    long non_finite = 0;
    double lowest = 1e30, highest = -1e30;  // the liquid's temperatures at the end
};

// Runs the slab at Stefan number `stefan` until `layers` lattice layers have melted in the central
// columns (or `time_limit`), with fixed steps of `dt`.
StefanRun run_stefan(double stefan, int layers, double dt, double time_limit) {
    const int width = 8;          // lattice vertices across the slab (y and z)
    const int length = layers + 4;  // vertices along x
    const double side = width * double(kR0), plate_thickness = 4 * double(kR0);
    const double span = plate_thickness + (length + 2) * double(kR0);
    SimulationSetup setup =
        test::empty_domain(Vec3{0, 0, 0}, Vec3{Real(span + 0.2), Real(side + 0.2), Real(side + 0.2)}, kR0, Real(dt));
    setup.params.gravity = Vec3{0, 0, 0};
    setup.params.heat.enabled = true;
    setup.params.heat.fluid_diffusivity = Real(kDiffusivity);
    setup.params.heat.fluid_capacity = Real(kCapacity);
    setup.params.heat.max_substeps = 64;
    const double centre_y = 0.1 + side / 2, centre_z = 0.1 + side / 2;

    SolidSetup plate;
    plate.name = "plate";
    plate.kind = SolidKind::kElastic;
    plate.density = kDensity;
    plate.thermal_diffusivity = Real(kDiffusivity);
    plate.heat_capacity = Real(1e6 * kCapacity);
    plate.melting_point = Real(1e4);  // never reached: it makes the plate a lattice like the solid's
    const double plate_x = 0.1 + plate_thickness / 2;
    test::add_box_solid(setup, Vec3d(plate_thickness, side, side), Vec3d(plate_x, centre_y, centre_z), plate, Vec3{0, 0, 0},
                        [](const Vec3&) { return true; });
    double plate_face = -1e30;
    for (std::size_t i = 0; i < setup.position.size(); ++i)
        if (setup.object[i] == 0) plate_face = std::max(plate_face, double(setup.position[i].x));
    plate_face += 0.5 * double(kR0);  // the lattice's last layer lies r0 / 2 inside the face

    SolidSetup solid;
    solid.name = "solid";
    solid.kind = SolidKind::kElastic;
    solid.density = kDensity;
    solid.thermal_diffusivity = Real(kDiffusivity);
    solid.heat_capacity = Real(kCapacity);
    solid.melting_point = Real(kMelt);
    solid.latent_heat = Real((kWall - kMelt) / stefan * kCapacity / kDensity);
    const double slab_length = length * double(kR0);  // its lattice lies r0 / 2 inside its faces
    const std::size_t first_solid = setup.position.size();
    test::add_box_solid(setup, Vec3d(slab_length, side, side),
                        Vec3d(plate_face + slab_length / 2, centre_y, centre_z), solid, Vec3{0, 0, 0},
                        [](const Vec3&) { return true; });
    double solid_start = 1e30;
    for (std::size_t i = first_solid; i < setup.position.size(); ++i)
        solid_start = std::min(solid_start, double(setup.position[i].x));
    INFO("plate face " << plate_face << " m, solid's first layer " << solid_start << " m");
    REQUIRE(std::fabs(solid_start - plate_face - 0.5 * double(kR0)) < 0.01 * double(kR0));
    for (std::size_t i = 0; i < setup.position.size(); ++i)
        setup.temperature.push_back(Real(setup.object[i] == 0 ? kWall : kMelt));

    // The central columns: 4 x 4 lattice columns, two from each free side.
    auto central = [&](const Vec3& x) {
        return std::fabs(double(x.y) - centre_y) < 2 * double(kR0) && std::fabs(double(x.z) - centre_z) < 2 * double(kR0);
    };
    long columns = 0;
    for (std::size_t i = first_solid; i < setup.position.size(); ++i)
        columns += central(setup.position[i]) && std::fabs(double(setup.position[i].x) - solid_start) < 0.5 * double(kR0);
    REQUIRE(columns == 16);
    const long central_total = [&] {
        long n = 0;
        for (std::size_t i = first_solid; i < setup.position.size(); ++i) n += central(setup.position[i]);
        return n;
    }();

    // One thread, for the simulation and for the host's work on it, and the particles read only on
    // steps where something melted: a thousand short steps of 2,000 particles, each a handful of
    // parallel regions, crawl when a team of threads shares busy cores with another test (214 s
    // under ctest -j2 against 3 s alone).
    const test::OneHostThread one_host_thread;
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 1);
    StefanRun r;
    r.analytic = stefan_lambda(stefan);
    double sum_st = 0, sum_tt = 0;  // least squares of s = 2 λ sqrt(α t) over the layers' crossings
    int crossed = 0;
    HostParticles p;
    double melted_before = 0;
    while (sim->time() < time_limit && crossed < layers) {
        sim->step();
        const double melted_now = sim->last_report().value("melted");
        if (melted_now == melted_before) continue;
        melted_before = melted_now;
        sim->download(p);
        long left = 0;
        for (std::size_t i = 0; i < p.position.size(); ++i)
            left += p.object[i] == 1 && p.type[i] != kFluid && central(p.position[i]);
        const double melted_layers = double(central_total - left) / double(columns);
        // Each whole layer the mean count passes is a point s = n r0 at this step's time; the first
        // two, within the kernel's reach of the plate, are left out of the fit.
        while (crossed < layers && melted_layers >= crossed + 1) {
            ++crossed;
            if (crossed <= 2) continue;
            const double s = crossed * double(kR0), root = 2 * std::sqrt(kDiffusivity * sim->time());
            sum_st += s * root;
            sum_tt += root * root;
        }
    }
    r.layers = crossed;
    r.time = sim->time();
    sim->download(p);
    r.lambda = sum_tt > 0 ? sum_st / sum_tt : 0;
    for (std::size_t i = 0; i < p.position.size(); ++i) {
        r.non_finite += std::isfinite(double(p.position[i].x)) && std::isfinite(double(p.temperature[i])) ? 0 : 1;
        if (p.type[i] != kFluid) continue;
        r.lowest = std::min(r.lowest, double(p.temperature[i]));
        r.highest = std::max(r.highest, double(p.temperature[i]));
    }
    return r;
}

}  // namespace

TEST_CASE("a solid at its melting point against a hot plate melts as the one-phase Stefan problem says") {
    // St 0.1 to six layers only: past about 1,300 steps the melt layer, free at its sides with no
    // gravity, starts to flow out of the gap (docs/melting.md, "Limits").
    const struct {
        double stefan;
        int layers;
    } cases[] = {{1.0, 10}, {0.3, 10}, {0.1, 6}};
    for (const auto& c : cases) {
        const double st = c.stefan;
        const StefanRun r = run_stefan(st, c.layers, 0.001, 5);
        MESSAGE("St " << st << ": λ fitted " << r.lambda << ", analytic " << r.analytic << " (" << 100 * (r.lambda / r.analytic - 1)
                      << "%), " << r.layers << " layers by t = " << r.time << " s, liquid " << r.lowest << " .. " << r.highest
                      << " °C");
        CHECK(r.non_finite == 0);
        CHECK(r.layers == c.layers);
        CHECK(r.lambda == doctest::Approx(r.analytic).epsilon(0.05));
        CHECK(r.lowest >= kMelt - 1e-3);
        CHECK(r.highest <= kWall + 1e-3);
    }
}
