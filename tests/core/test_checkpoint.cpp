// Checkpoint and restart through the Simulation interface (algorithms/state_archive.hpp): a run
// that saves its state half way, loaded into a new simulation of the same setup, ends bitwise where
// the uninterrupted run ends; a state that does not fit the setup is refused by name.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "simulation/factory.hpp"
#include "common/errors.hpp"
#include "test_setups.hpp"
#include "tests/skip.hpp"

using namespace mw;

namespace {
bool bitwise_equal(const HostParticles& a, const HostParticles& b) {
    return a.position.size() == b.position.size() &&
           !std::memcmp(a.position.data(), b.position.data(), a.position.size() * sizeof(Vec3)) &&
           !std::memcmp(a.velocity.data(), b.velocity.data(), a.velocity.size() * sizeof(Vec3)) &&
           !std::memcmp(a.density.data(), b.density.data(), a.density.size() * sizeof(Real)) &&
           !std::memcmp(a.pressure.data(), b.pressure.data(), a.pressure.size() * sizeof(Real)) && a.type == b.type;
}

// A box thrown into a pool in CFL mode (the step size's limit and growth are state): an elastic
// box under two-way coupling, the correction and the lookahead (the regions' rotations, the
// surface normals and the pending contact impulses are state), meeting the water in the run's
// second half.
SimulationSetup column_and_thrown_box() {
    SimulationSetup setup = test::box_thrown_onto_pool(SolidKind::kElastic, 500, 0.11);
    setup.params.coupling.correction = true;
    setup.params.coupling.predict_solids = true;
    return setup;
}
}  // namespace

TEST_CASE("a run resumed from its saved state ends bitwise where the uninterrupted run ends") {
    const SimulationSetup setup = column_and_thrown_box();
    const int first = 25, second = 25;
    const std::unique_ptr<Simulation> whole = create_openmp_simulation(setup, 0);
    const HostParticles uninterrupted = test::run_steps(*whole, first + second);

    StateArchive saved;
    double saved_time = 0;
    {
        const std::unique_ptr<Simulation> before = create_openmp_simulation(setup, 0);
        test::run_steps(*before, first);
        before->save_state(saved);
        saved_time = before->time();
    }
    const std::unique_ptr<Simulation> resumed = create_openmp_simulation(setup, 0);
    resumed->load_state(saved);
    CHECK(resumed->time() == saved_time);
    CHECK(resumed->last_report().step == first);
    const HostParticles after = test::run_steps(*resumed, second);
    CHECK(resumed->last_report().step == first + second);
    CHECK(resumed->time() == whole->time());
    CHECK(bitwise_equal(after, uninterrupted));
    // The state really is needed: the same steps from the setup's own start end elsewhere.
    const std::unique_ptr<Simulation> fresh = create_openmp_simulation(setup, 0);
    CHECK_FALSE(bitwise_equal(test::run_steps(*fresh, second), uninterrupted));
    // And the run did something the saved state had to carry: the box moved, the step size varied.
    CHECK(whole->last_report().solid_max_speed > 0.1);
}

TEST_CASE("the solids' state travels: without the pending contact impulses the resumed run differs") {
    // The correction's impulses on the SBPs wait for the next step's coupling (solid_contact.hpp):
    // a restart that dropped them would lose that momentum. Saved at the first step after the
    // box has met the water that leaves some pending.
    const SimulationSetup setup = column_and_thrown_box();
    auto pending = [](const Simulation& sim) {
        double sum = 0;
        for (const auto& p : sim.pending_contact_impulse()) sum += std::abs(p[0]) + std::abs(p[1]) + std::abs(p[2]);
        return sum;
    };
    StateArchive saved;
    int saved_at = 0;
    {
        const std::unique_ptr<Simulation> before = create_openmp_simulation(setup, 0);
        for (saved_at = 1; saved_at <= 60; ++saved_at) {
            before->step();
            if (saved_at >= 20 && pending(*before) > 0) break;
        }
        REQUIRE(saved_at <= 60);
        before->save_state(saved);
    }
    const std::unique_ptr<Simulation> whole = create_openmp_simulation(setup, 0);
    const HostParticles uninterrupted = test::run_steps(*whole, saved_at + 20);
    StateArchive without_impulses;
    for (StateBlock block : saved.blocks()) {
        if (block.name == "solids.sbp_impulse") std::fill(block.bytes.begin(), block.bytes.end(), 0);
        without_impulses.add(block);
    }
    const std::unique_ptr<Simulation> with_them = create_openmp_simulation(setup, 0);
    with_them->load_state(saved);
    CHECK(bitwise_equal(test::run_steps(*with_them, 20), uninterrupted));
    const std::unique_ptr<Simulation> without = create_openmp_simulation(setup, 0);
    without->load_state(without_impulses);
    CHECK_FALSE(bitwise_equal(test::run_steps(*without, 20), uninterrupted));
}

TEST_CASE("a saved state that does not fit the setup is refused, naming what differs") {
    const SimulationSetup setup = column_and_thrown_box();
    StateArchive saved;
    {
        const std::unique_ptr<Simulation> sim = create_openmp_simulation(setup, 0);
        test::run_steps(*sim, 2);
        sim->save_state(saved);
    }
    auto load_message = [&](const SimulationSetup& other, const StateArchive& archive) {
        const std::unique_ptr<Simulation> sim = create_openmp_simulation(other, 0);
        try {
            sim->load_state(archive);
        } catch (const InputError& e) {
            return std::string(e.what());
        }
        return std::string("loaded");
    };
    // Another scene: a taller tank has as many particles but its walls elsewhere.
    SimulationSetup taller = column_and_thrown_box();
    for (std::size_t i = 0; i < taller.position.size(); ++i)
        if (taller.type[i] == kStaticBoundary) taller.position[i].y += 0.001f;
    CHECK(load_message(taller, saved).find("static boundary") != std::string::npos);
    // Fewer particles.
    SimulationSetup smaller = test::fluid_in_box({0, 0, 0}, {0.6f, 0.5f, 0.2f}, {0, 0, 0}, {0.2f, 0.2f, 0.2f}, 0.02f,
                                                 0.004f);
    CHECK(load_message(smaller, saved).find("particles") != std::string::npos);
    // A block missing, and one of another element size (another precision).
    StateArchive missing, resized;
    for (const StateBlock& block : saved.blocks()) {
        if (block.name != "store.velocity") missing.add(block);
        StateBlock copy = block;
        if (copy.name == "time") {
            copy.element_bytes = 4;
            copy.count = 2;
        }
        resized.add(copy);
    }
    CHECK(load_message(setup, missing).find("store.velocity") != std::string::npos);
    CHECK(load_message(setup, resized).find("'time'") != std::string::npos);
}

TEST_CASE("CUDA: a state saved on CUDA continues on OpenMP, and the other way round") {
    if (!cuda_backend_info().available) {
        MW_SKIP(cuda_backend_info().description);
        return;
    }
    // Saved after 20 steps, with the box in the water: the loading backend holds exactly the state
    // saved, and its next step is the saving backend's next step, to rounding. Not compared over
    // many steps: the box's entry is chaotic (measured on an H200): from step 15 on,
    // the lookahead and the corrections turn the backends' rounding into a 6e-5 m difference in
    // a single step, and the two backends' runs are 7.9e-3 m apart after 40 steps. One step from
    // OpenMP's state of step 20 differed by at most 1.1e-5 m (and by 1.3e-4 m from step 16's);
    // a field lost in transfer would move fluid by about its velocity times the step (an
    // estimate: 1 m/s by 3.5 ms, 3.5e-3 m).
    const SimulationSetup setup = column_and_thrown_box();
    auto create = [&](bool cuda) { return cuda ? create_cuda_simulation(setup) : create_openmp_simulation(setup, 0); };
    for (const bool save_on_cuda : {true, false}) {
        CAPTURE(save_on_cuda);
        const std::unique_ptr<Simulation> saver = create(save_on_cuda);
        test::run_steps(*saver, 20);
        StateArchive saved;
        saver->save_state(saved);
        HostParticles as_saved;
        saver->download(as_saved);
        const std::unique_ptr<Simulation> loader = create(!save_on_cuda);
        loader->load_state(saved);
        HostParticles as_loaded;
        loader->download(as_loaded);
        CHECK(as_loaded.type == as_saved.type);
        CHECK(std::memcmp(as_loaded.position.data(), as_saved.position.data(), as_saved.position.size() * sizeof(Vec3)) == 0);
        CHECK(std::memcmp(as_loaded.velocity.data(), as_saved.velocity.data(), as_saved.velocity.size() * sizeof(Vec3)) == 0);
        CHECK(loader->time() == saver->time());
        const HostParticles saver_next = test::run_steps(*saver, 1), loader_next = test::run_steps(*loader, 1);
        const double worst = test::largest_position_difference(saver_next, loader_next);
        MESSAGE("one step from the transferred state: largest position difference " << worst << " m");
        CHECK(worst < 5e-4);  // r0 / 40
    }
}
