// The OpenMP instantiation of the 2D simulation, for both kernels (a file of its own, so that it
// compiles beside the 3D ones).
#define MW_BACKEND_OPENMP
#include "simulation/backend_simulation.hpp"

MW_BACKEND_BEGIN

std::unique_ptr<Simulation> make_cubic_spline_2d_simulation(const SimulationSetup& setup, int threads) {
    return std::make_unique<BackendSimulation<CubicSpline2D>>(setup, threads);
}
std::unique_ptr<Simulation> make_wendland_c2_2d_simulation(const SimulationSetup& setup, int threads) {
    return std::make_unique<BackendSimulation<WendlandC2_2D>>(setup, threads);
}

MW_BACKEND_END
