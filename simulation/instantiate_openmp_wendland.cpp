// The OpenMP instantiation of the simulation for the Wendland C2 kernel (a file of its own, so
// that it compiles beside the cubic spline's).
#define MW_BACKEND_OPENMP
#include "simulation/backend_simulation.hpp"

MW_BACKEND_BEGIN

std::unique_ptr<Simulation> make_wendland_c2_simulation(const SimulationSetup& setup, int threads) {
    return std::make_unique<BackendSimulation<WendlandC2_3D>>(setup, threads);
}

MW_BACKEND_END
