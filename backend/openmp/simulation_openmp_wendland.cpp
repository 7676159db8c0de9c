// The OpenMP instantiation of the algorithms for the Wendland C2 kernel (a file of its own, so
// that it compiles beside the cubic spline's).
#define MW_BACKEND_OPENMP
#include "algorithms/time_step.hpp"

MW_BACKEND_BEGIN

std::unique_ptr<Simulation> make_wendland_c2_simulation(const SimulationSetup& setup) {
    return std::make_unique<BackendSimulation<WendlandC2_3D>>(setup);
}

MW_BACKEND_END
