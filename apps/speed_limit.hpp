// The runaway guard's speed limit (scene key solver.max_speed). A blow-up that PCISPH's density
// error does not show (the fluid thrown about at thousands of m/s while the CFL step shrinks to
// its floor, so that the run grinds on for ever) shows in the speeds: nothing in a scene can move
// much faster than its fastest start plus a fall through the whole domain, since energy only
// leaves a scene (viscosity, inelastic contact) and emitters bring their own speed.
#pragma once
#include <string>

#include "simulation/simulation.hpp"
#include "apps/scene.hpp"

namespace mw {

// How many times the speed scale the default limit allows: splashes and jets reach a few times
// it (docs/scenes.md gives the shipped scenes' peaks), while a particle at 20 times it carries 400
// times the energy per mass that any part of the scene could have gained.
constexpr double kRunawaySpeedFactor = 20;

struct SpeedLimit {
    double start = 0;  // m/s: the fastest initial velocity of fluid or solid, or emitter speed
    double fall = 0;   // m/s: sqrt(2 |g| L), L the domain's extent along gravity
    double limit = 0;  // m/s; 0: no guard (a scene without gravity, motion or emitters)
    bool automatic = true;  // the limit is kRunawaySpeedFactor (start + fall), not solver.max_speed
    double scale() const { return start + fall; }
};

SpeedLimit speed_limit(const Scene& scene, const SimulationSetup& setup);

// sqrt(2 |g| L), L the domain's extent along gravity (0 without gravity), m/s: a fall through
// the whole domain.
double fall_speed(const Scene& scene);

// The limit and where it came from, as `info` and the run's stop message say it:
// "solver.max_speed 74.12 m/s (20 times the scene's 3.71 m/s: ...)", or "solver.max_speed 50 m/s".
std::string describe(const SpeedLimit& limit);

}  // namespace mw
