// Melting (algorithms/melting.hpp): the outside-in phase change, the regions rebuilt over the
// lattice left, latent heat in the heat content, and checkpoints taken mid-melt.
#include <doctest/doctest.h>

#include <cmath>
#include <cstring>
#include <map>

#include "../skip.hpp"
#include "algorithms/lsm_regions.hpp"
#include "algorithms/melting_regions.hpp"
#include "simulation/factory.hpp"
#include "test_setups.hpp"

using namespace mw;

namespace {

constexpr Real kR0 = 0.02;

SolidSetup melting_solid(double melting_point, double latent_heat) {
    SolidSetup solid;
    solid.name = "ice";
    solid.kind = SolidKind::kElastic;
    solid.density = 900;
    solid.heat_capacity = Real(1.9e6);
    solid.thermal_diffusivity = Real(1e-3);
    solid.melting_point = Real(melting_point);
    solid.latent_heat = Real(latent_heat);
    return solid;
}

long count_type(const HostParticles& p, std::uint8_t type) {
    return std::count(p.type.begin(), p.type.end(), type);
}

// A lattice cube of n³ vertices as an elastic object's IBPs (no mesh), for the region tests.
SimulationSetup lattice_cube(int n, const std::vector<std::uint8_t>& keep = {}) {
    SimulationSetup setup;
    setup.params.boundary.walls = false;
    SolidSetup solid;
    solid.name = "cube";
    solid.spacing = kR0;
    solid.gp_offsets.assign(1, 0);
    std::size_t k = 0;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x, ++k) {
                if (!keep.empty() && !keep[k]) continue;
                solid.ibp.push_back(std::uint32_t(setup.position.size()));
                solid.lattice.push_back({x, y, z});
                setup.position.push_back(Vec3{Real(x * kR0), Real(y * kR0), Real(z * kR0)});
                setup.type.push_back(kInnerBoundary);
            }
    setup.velocity.assign(setup.position.size(), Vec3{0, 0, 0});
    setup.object.assign(setup.position.size(), 0);
    setup.solids.push_back(solid);
    return setup;
}

}  // namespace

TEST_CASE("a melting object is its lattice: a vertex missing a one-ring neighbour is an SBP") {
    SimulationSetup setup = test::empty_domain(Vec3{0, 0, 0}, Vec3{0.3f, 0.3f, 0.3f}, kR0, Real(0.002));
    setup.params.heat.enabled = true;
    test::add_box_solid(setup, Vec3d(0.13, 0.13, 0.13), Vec3d(0.15, 0.15, 0.15), melting_solid(0, 0), Vec3{0, 0, 0});
    const SolidSetup& solid = setup.solids.at(0);
    REQUIRE(solid.gp.empty());
    REQUIRE(solid.sbp.empty());
    int lo[3] = {1 << 30, 1 << 30, 1 << 30}, hi[3] = {-(1 << 30), -(1 << 30), -(1 << 30)};
    for (const auto& c : solid.lattice)
        for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], c[a]), hi[a] = std::max(hi[a], c[a]);
    const long side[3] = {hi[0] - lo[0] + 1, hi[1] - lo[1] + 1, hi[2] - lo[2] + 1};
    REQUIRE(long(solid.lattice.size()) == side[0] * side[1] * side[2]);  // a box samples a full block
    long sbp = 0, ibp = 0;
    for (std::uint32_t i : solid.ibp) (setup.type[i] == kSurfaceBoundary ? sbp : ibp) += 1;
    MESSAGE("lattice " << side[0] << " x " << side[1] << " x " << side[2] << ": " << sbp << " SBPs, " << ibp << " IBPs");
    CHECK(ibp == (side[0] - 2) * (side[1] - 2) * (side[2] - 2));
    CHECK(sbp + ibp == long(solid.lattice.size()));
}

TEST_CASE("regions rebuilt over the vertices left are those of an object built from them alone") {
    // A 7³ cube losing its outer shell and, inside, a few scattered vertices (holes make the
    // breadth-first regions differ from cubes).
    // Rebuilt twice near what went (the shell, then the holes, as melting rebuilds), and once
    // everywhere (as a checkpoint's load does).
    const int n = 7;
    std::vector<std::uint8_t> alive(n * n * n, 1);
    std::vector<std::uint32_t> shell, holes;
    for (int z = 0; z < n; ++z)
        for (int y = 0; y < n; ++y)
            for (int x = 0; x < n; ++x) {
                const std::uint32_t k = std::uint32_t((z * n + y) * n + x);
                if (x == 0 || y == 0 || z == 0 || x == n - 1 || y == n - 1 || z == n - 1) shell.push_back(k);
                else if ((x == 3 && y == 3 && z == 3) || (x == 2 && y == 4 && z == 3) || (x == 4 && y == 2 && z == 2))
                    holes.push_back(k);
            }
    const SimulationSetup whole = lattice_cube(n);
    const auto& lattice = whole.solids[0].lattice;
    const int w = whole.solids[0].region_half_width;
    LsmHostLayout rebuilt = build_lsm_layout(whole);
    for (std::uint32_t k : shell) alive[k] = 0;
    rebuild_elastic_object_regions(rebuilt, lattice, w, 0, alive, &shell);
    for (std::uint32_t k : holes) alive[k] = 0;
    rebuild_elastic_object_regions(rebuilt, lattice, w, 0, alive, &holes);
    LsmHostLayout everywhere = build_lsm_layout(whole);
    rebuild_elastic_object_regions(everywhere, lattice, w, 0, alive);
    const SimulationSetup left = lattice_cube(n, alive);
    const LsmHostLayout fresh = build_lsm_layout(left);
    // Slot of each vertex left in the fresh build.
    std::vector<std::uint32_t> fresh_slot(alive.size(), 0);
    for (std::size_t k = 0, f = 0; k < alive.size(); ++k)
        if (alive[k]) fresh_slot[k] = std::uint32_t(f++);
    long compared = 0, mismatched = 0;
    for (const LsmHostLayout* layout : {&rebuilt, &everywhere}) {
        const LsmHostLayout& r = *layout;
        for (std::size_t k = 0; k < alive.size(); ++k) {
            const std::uint32_t s = std::uint32_t(k), f = fresh_slot[k];
            if (!alive[k]) {
                CHECK(r.region_end[s] == r.region_offsets[s]);
                CHECK(r.ibp_regions_end[s] == r.ibp_regions_begin[s]);
                continue;
            }
            ++compared;
            std::vector<std::array<int, 3>> a, b;
            for (std::uint32_t m = r.region_offsets[s]; m < r.region_end[s]; ++m) a.push_back(lattice[r.member_index[m]]);
            for (std::uint32_t m = fresh.region_offsets[f]; m < fresh.region_end[f]; ++m)
                b.push_back(left.solids[0].lattice[fresh.member_index[m]]);
            const bool same = a == b && r.ibp_split_mass[s] == fresh.ibp_split_mass[f] &&
                              r.ibp_regions_end[s] - r.ibp_regions_begin[s] == fresh.ibp_regions_end[f] - fresh.ibp_regions_begin[f] &&
                              r.region_mass[s] == fresh.region_mass[f] &&
                              std::memcmp(&r.region_c0[s], &fresh.region_c0[f], sizeof(Vec3)) == 0 &&
                              std::memcmp(&r.region_A0[s], &fresh.region_A0[f], sizeof(SymMat3)) == 0 &&
                              std::memcmp(&r.region_inertia_inv[s], &fresh.region_inertia_inv[f], sizeof(SymMat3)) == 0;
            mismatched += !same;
        }
    }
    MESSAGE(compared << " regions compared");
    CHECK(compared == 2 * (5 * 5 * 5 - 3));
    CHECK(mismatched == 0);
}

TEST_CASE("a step's melting updates the lattice on the device as the host would, bit for bit") {
    // A 9³ cube (w 2, and w 1) losing, step by step, its outer shell, a few scattered vertices
    // inside, and then a whole face layer: after each step the device's exposed vertices and
    // regions (melting_regions.hpp) against the host's (one-ring counts, and
    // rebuild_elastic_object_regions near what went).
    const int n = 9;
    for (const int w : {2, 1}) {
        CAPTURE(w);
        SimulationSetup whole = lattice_cube(n);
        whole.solids[0].region_half_width = w;
        const auto& lattice = whole.solids[0].lattice;
        LsmHostLayout host = build_lsm_layout(whole);
        const std::size_t count = lattice.size();
        std::vector<std::uint8_t> alive(count, 1);
        std::vector<std::uint8_t> ring = lattice_one_ring_counts(lattice);

        const DeviceContext device;
        std::vector<std::int32_t> cell_slot, slot_coord(3 * count, 0);
        const MeltingGrid g = melting_grid(lattice, 0, w, 26, cell_slot, slot_coord);
        DeviceArray<std::int32_t> cells, coords;
        cells.upload(cell_slot);
        coords.upload(slot_coord);
        DeviceArray<std::uint8_t> melts(count), exposed(count), reach(cell_slot.size()), reach_next(cell_slot.size());
        // The store: one particle per slot, in slot order, typed by its one-ring.
        std::vector<std::uint32_t> identity(count);
        std::vector<std::uint8_t> types(count);
        for (std::size_t k = 0; k < count; ++k)
            identity[k] = std::uint32_t(k), types[k] = ring[k] == 26 ? kInnerBoundary : kSurfaceBoundary;
        DeviceArray<std::uint32_t> slot_map;
        DeviceArray<std::uint8_t> type;
        DeviceArray<std::int32_t> solid_slot(count), object(count);
        DeviceArray<Real> density(count);
        slot_map.upload(identity);
        type.upload(types);
        DeviceArray<Vec3> rest, c0;
        DeviceArray<Real> mass, split_mass, region_mass;
        DeviceArray<std::uint32_t> offsets, regions_begin, region_end, regions_end, members;
        DeviceArray<SymMat3> A0, inertia_inv;
        rest.upload(host.ibp_rest);
        mass.upload(host.ibp_mass);
        offsets.upload(host.region_offsets);
        regions_begin.upload(host.ibp_regions_begin);
        region_end.upload(host.region_end);
        regions_end.upload(host.ibp_regions_end);
        members.upload(host.member_index);
        split_mass.upload(host.ibp_split_mass);
        region_mass.upload(host.region_mass);
        c0.upload(host.region_c0);
        A0.upload(host.region_A0);
        inertia_inv.upload(host.region_inertia_inv);
        MeltingLatticeData d;
        d.cell_slot = cells.cview().data();
        d.slot_coord = coords.cview().data();
        d.melts = melts.cview().data();
        d.exposed = exposed.view().data();
        d.reach = reach.view().data();
        d.reach_next = reach_next.view().data();
        d.regions = MeltingRegionArrays{rest.cview().data(), mass.cview().data(), offsets.cview().data(),
                                        regions_begin.cview().data(), region_end.view().data(), regions_end.view().data(),
                                        members.view().data(), split_mass.view().data(), region_mass.view().data(),
                                        c0.view().data(), A0.view().data(), inertia_inv.view().data()};
        d.particles = PhaseChangeData{slot_map.view().data(), type.view().data(), solid_slot.view().data(),
                                      object.view().data(), density.view().data(), Real(1000)};

        // The three steps' melts, as local indices.
        std::vector<std::vector<std::uint32_t>> steps(3);
        for (int z = 0; z < n; ++z)
            for (int y = 0; y < n; ++y)
                for (int x = 0; x < n; ++x) {
                    const std::uint32_t k = std::uint32_t((z * n + y) * n + x);
                    const bool shell = x == 0 || y == 0 || z == 0 || x == n - 1 || y == n - 1 || z == n - 1;
                    if (shell) steps[0].push_back(k);
                    else if ((x == 4 && y == 4 && z == 4) || (x == 3 && y == 5 && z == 4) || (x == 5 && y == 2 && z == 3))
                        steps[1].push_back(k);
                    else if (z == 1) steps[2].push_back(k);
                }
        long exposed_total = 0, regions_compared = 0, mismatched = 0;
        for (const std::vector<std::uint32_t>& gone : steps) {
            // The host: who is exposed, then the regions near what went.
            std::vector<std::uint8_t> flags(count, 0), exposed_host(count, 0);
            for (const std::uint32_t k : gone) flags[k] = 1, alive[k] = 0;
            const std::vector<std::uint8_t> left = lattice_one_ring_counts(lattice, alive);
            for (std::size_t k = 0; k < count; ++k) {
                if (!alive[k]) continue;
                exposed_host[k] = ring[k] == 26 && left[k] < 26;
                ring[k] = left[k];
            }
            rebuild_elastic_object_regions(host, lattice, w, 0, alive, &gone);
            // The device.
            melts.upload(flags);
            update_melting_lattice(device, g, d);
            CHECK(exposed.to_host() == exposed_host);
            const std::vector<std::uint32_t> slots_d = slot_map.to_host();
            const std::vector<std::uint8_t> types_d = type.to_host();
            long type_mismatches = 0;
            for (std::size_t k = 0; k < count; ++k) {
                CHECK((slots_d[k] != kMeltedSlot) == bool(alive[k]));
                const std::uint8_t expected = !alive[k] ? kFluid : ring[k] == 26 ? kInnerBoundary : kSurfaceBoundary;
                type_mismatches += types_d[k] != expected;
            }
            CHECK(type_mismatches == 0);
            exposed_total += std::count(exposed_host.begin(), exposed_host.end(), std::uint8_t(1));
            const std::vector<std::uint32_t> end_d = region_end.to_host(), ends_d = regions_end.to_host(), members_d = members.to_host();
            const std::vector<Real> split_d = split_mass.to_host(), mass_d = region_mass.to_host();
            const std::vector<Vec3> c0_d = c0.to_host();
            const std::vector<SymMat3> A0_d = A0.to_host(), inverse_d = inertia_inv.to_host();
            for (std::size_t s = 0; s < count; ++s) {
                ++regions_compared;
                bool same = end_d[s] == host.region_end[s] && ends_d[s] == host.ibp_regions_end[s] &&
                            std::memcmp(&mass_d[s], &host.region_mass[s], sizeof(Real)) == 0;
                if (alive[s]) {
                    for (std::uint32_t m = host.region_offsets[s]; m < host.region_end[s]; ++m)
                        same = same && members_d[m] == host.member_index[m];
                    same = same && std::memcmp(&split_d[s], &host.ibp_split_mass[s], sizeof(Real)) == 0 &&
                           std::memcmp(&c0_d[s], &host.region_c0[s], sizeof(Vec3)) == 0 &&
                           std::memcmp(&A0_d[s], &host.region_A0[s], sizeof(SymMat3)) == 0 &&
                           std::memcmp(&inverse_d[s], &host.region_inertia_inv[s], sizeof(SymMat3)) == 0;
                }
                mismatched += !same;
            }
        }
        MESSAGE("w " << w << ": " << exposed_total << " vertices exposed, " << regions_compared << " regions compared");
        CHECK(exposed_total > 7 * 7 * 7 - 5 * 5 * 5);  // the shell's step exposes the 7³ cube's surface, and more follow
        CHECK(mismatched == 0);
    }
}

TEST_CASE("an object above its melting point melts from the outside in, one lattice layer a step, to the last particle") {
    // No gravity, latent heat 0, every particle 30 K above the melting point: each step the SBPs
    // melt and the IBPs they leave exposed become the next SBPs.
    SimulationSetup setup = test::empty_domain(Vec3{0, 0, 0}, Vec3{0.3f, 0.3f, 0.3f}, kR0, Real(0.002));
    setup.params.gravity = Vec3{0, 0, 0};
    setup.params.heat.enabled = true;
    test::add_box_solid(setup, Vec3d(0.13, 0.13, 0.13), Vec3d(0.15, 0.15, 0.15), melting_solid(0, 0), Vec3{0, 0, 0});
    for (std::size_t i = 0; i < setup.position.size(); ++i) setup.temperature.push_back(Real(setup.object[i] < 0 ? 0 : 30));
    const long total = long(setup.solids[0].ibp.size());
    const long side = std::lround(std::cbrt(double(total)));
    REQUIRE(side * side * side == total);
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 0);
    REQUIRE(sim->counts().by_type[kFluid] == 0);
    const std::vector<std::string> stages = sim->stage_names();
    CHECK(std::find(stages.begin(), stages.end(), "melting") != stages.end());
    CHECK(std::find(stages.begin(), stages.end(), "pcisph") != stages.end());  // the fluid it will make
    long melted = 0;
    for (long inner = side - 2, step = 1; melted < total; inner -= 2, ++step) {
        const long solid_before = total - melted;
        const long solid_after = inner > 0 ? inner * inner * inner : 0;
        const HostParticles p = test::run_steps(*sim, 1);
        melted = sim->last_report().value("melted");
        INFO("step " << step);
        CHECK(melted == total - solid_after);
        CHECK(count_type(p, kFluid) == total - solid_after);
        CHECK(sim->counts().by_type[kFluid] == total - solid_after);
        // The layer left: its shell is SBPs, its inside IBPs.
        const long inside = inner > 2 ? (inner - 2) * (inner - 2) * (inner - 2) : 0;
        CHECK(count_type(p, kInnerBoundary) == inside);
        CHECK(count_type(p, kSurfaceBoundary) == solid_after - inside);
        CHECK(sim->counts().by_type[kSurfaceBoundary] == solid_after - inside);
        for (std::size_t i = 0; i < p.position.size(); ++i) {
            if (p.type[i] != kFluid) continue;
            REQUIRE(std::isfinite(double(p.position[i].x)));
            CHECK(p.object[i] == -1);
            // What a melted particle absorbed past the melting point went back to its temperature,
            // as the same heat per volume in the fluid's heat capacity (give or take the little
            // heat that crossed between the melted and the solid since).
            const double returned = 30.0 * double(setup.solids[0].heat_capacity / setup.params.heat.fluid_capacity);
            CHECK(std::fabs(double(p.temperature[i]) - returned) < 0.1);
        }
        REQUIRE(solid_before > solid_after);
        REQUIRE(step < 10);
    }
    // Everything melted: the solid stages have nothing left, and the steps go on.
    test::run_steps(*sim, 3);
    CHECK(sim->counts().by_type[kFluid] == total);
    CHECK(sim->last_report().value("melted") == total);
}

TEST_CASE("latent heat: an object at its melting point absorbs heat without warming, and the heat content counts it") {
    // A cube at 0 °C (its melting point) in water at 40 °C, with a latent heat too large to melt
    // anything in the run: the water cools, the cube stays at 0 °C, and Σ M (T + latent) holds.
    const Vec3 lo{0, 0, 0}, hi{0.3f, 0.24f, 0.3f};
    SimulationSetup setup = test::fluid_in_box(lo, hi, lo, Vec3{0.3f, 0.2f, 0.3f}, kR0, Real(0.002));
    setup.params.heat.enabled = true;
    setup.params.heat.fluid_diffusivity = Real(2e-3);
    SolidSetup solid = melting_solid(0, 1e12);
    solid.thermal_diffusivity = Real(2e-3);
    solid.density = 1000;  // floats in place
    test::add_box_solid(setup, Vec3d(0.1, 0.1, 0.1), Vec3d(0.15, 0.1, 0.15), solid, Vec3{0, 0, 0});
    for (std::size_t i = 0; i < setup.position.size(); ++i) setup.temperature.push_back(Real(setup.object[i] < 0 ? 40 : 0));
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 0);
    sim->step();
    const double first = sim->last_report().value("heat_content");
    const HostParticles p = test::run_steps(*sim, 40);
    double fluid_sum = 0, solid_highest = -1e30;
    long fluid = 0;
    for (std::size_t i = 0; i < p.position.size(); ++i) {
        if (p.type[i] == kFluid) {
            fluid_sum += double(p.temperature[i]);
            ++fluid;
        } else if (p.type[i] == kSurfaceBoundary || p.type[i] == kInnerBoundary) {
            solid_highest = std::max(solid_highest, double(p.temperature[i]));
        }
    }
    const double drift = std::fabs(sim->last_report().value("heat_content") / first - 1);
    MESSAGE("fluid mean " << fluid_sum / double(fluid) << " °C, solid highest " << solid_highest << " °C, heat drift "
                          << drift);
    CHECK(sim->last_report().value("melted") == 0);
    CHECK(solid_highest <= 1e-4);             // held at the melting point
    CHECK(fluid_sum / double(fluid) < 39.9);  // the water gave heat ...
    CHECK(drift < 1e-6);                      // ... which the cube holds as latent heat
}

namespace {
// An ice cube (melting point 0 °C, a little latent heat) dropped into warm water: it melts over
// the run, its particles leaving for the fluid a few at a time.
SimulationSetup ice_in_warm_water() {
    const Vec3 lo{0, 0, 0}, hi{0.3f, 0.3f, 0.3f};
    SimulationSetup setup = test::fluid_in_box(lo, hi, lo, Vec3{0.3f, 0.14f, 0.3f}, kR0, Real(0.002));
    setup.params.heat.enabled = true;
    setup.params.heat.fluid_diffusivity = Real(5e-3);
    setup.params.coupling.two_way = true;
    SolidSetup solid = melting_solid(0, 2000);
    solid.thermal_diffusivity = Real(5e-3);
    test::add_box_solid(setup, Vec3d(0.1, 0.1, 0.1), Vec3d(0.15, 0.17, 0.15), solid, Vec3{0, 0, 0});
    for (std::size_t i = 0; i < setup.position.size(); ++i) setup.temperature.push_back(Real(setup.object[i] < 0 ? 60 : -1));
    return setup;
}
}  // namespace

TEST_CASE("an ice cube in warm water melts gradually, and what melts joins the water") {
    const SimulationSetup setup = ice_in_warm_water();
    const long cube = long(setup.solids[0].ibp.size());
    const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 0);
    const long fluid_at_start = sim->counts().by_type[kFluid];
    long previous = 0, steps_with_melting = 0;
    for (int step = 0; step < 60; ++step) {
        sim->step();
        const long melted = sim->last_report().value("melted");
        REQUIRE(melted >= previous);
        steps_with_melting += melted > previous;
        previous = melted;
        REQUIRE(sim->last_report().lost_particles == 0);
    }
    HostParticles p;
    sim->download(p);
    MESSAGE(previous << " of " << cube << " particles melted in 60 steps, on " << steps_with_melting << " steps");
    CHECK(previous > 0);
    CHECK(previous < cube);  // gradually: not all at once
    CHECK(steps_with_melting > 1);
    CHECK(count_type(p, kFluid) == fluid_at_start + previous);
    for (std::size_t i = 0; i < p.position.size(); ++i) REQUIRE(std::isfinite(double(p.position[i].y)));
}

TEST_CASE("a checkpoint taken mid-melt resumes bitwise where the whole run ends") {
    const test::SplitRun run = test::run_split(ice_in_warm_water(), 30, 20);
    MESSAGE(run.saved_report.value("melted") << " melted at the checkpoint, " << run.whole_report.value("melted") << " at the end");
    REQUIRE(run.saved_report.value("melted") > 0);
    REQUIRE(run.whole_report.value("melted") > run.saved_report.value("melted"));  // melting went on after it
    CHECK(run.resumed_report.value("melted") == run.whole_report.value("melted"));
    CHECK(run.resumed.type == run.uninterrupted.type);
    CHECK(std::memcmp(run.resumed.position.data(), run.uninterrupted.position.data(),
                      run.resumed.position.size() * sizeof(Vec3)) == 0);
    CHECK(std::memcmp(run.resumed.temperature.data(), run.uninterrupted.temperature.data(),
                      run.resumed.temperature.size() * sizeof(Real)) == 0);
}

TEST_CASE("only elastic objects melt, and only with heat conduction") {
    SimulationSetup setup = test::empty_domain(Vec3{0, 0, 0}, Vec3{0.3f, 0.3f, 0.3f}, kR0, Real(0.002));
    SolidSetup solid = melting_solid(0, 0);
    solid.kind = SolidKind::kRigid;
    test::add_box_solid(setup, Vec3d(0.1, 0.1, 0.1), Vec3d(0.15, 0.15, 0.15), solid, Vec3{0, 0, 0});
    setup.params.heat.enabled = true;
    setup.temperature.assign(setup.position.size(), Real(0));
    CHECK_THROWS_WITH_AS(create_openmp_simulation(setup, 0), doctest::Contains("only elastic objects"), InputError);
    setup.solids[0].kind = SolidKind::kElastic;
    setup.params.heat.enabled = false;
    CHECK_THROWS_WITH_AS(create_openmp_simulation(setup, 0), doctest::Contains("needs heat conduction"), InputError);
}

TEST_CASE("CUDA: an object melts layer by layer as on OpenMP") {
    if (!cuda_backend_info().available) {
        MW_SKIP("no CUDA device: the cross-backend melting test needs one");
        return;
    }
    SimulationSetup setup = test::empty_domain(Vec3{0, 0, 0}, Vec3{0.3f, 0.3f, 0.3f}, kR0, Real(0.002));
    setup.params.heat.enabled = true;
    test::add_box_solid(setup, Vec3d(0.13, 0.13, 0.13), Vec3d(0.15, 0.15, 0.15), melting_solid(0, 0), Vec3{0, 0, 0});
    for (std::size_t i = 0; i < setup.position.size(); ++i) setup.temperature.push_back(Real(setup.object[i] < 0 ? 0 : 30));
    const test::OpenmpAndCuda both = test::run_openmp_and_cuda(setup, 2);
    CHECK(both.cuda_report.value("melted") == both.openmp_report.value("melted"));
    CHECK(both.cuda.type == both.openmp.type);
    const double moved = test::largest_position_difference(both.openmp, both.cuda);
    MESSAGE("largest position difference " << moved << " m");
    CHECK(moved < 1e-5);
}
