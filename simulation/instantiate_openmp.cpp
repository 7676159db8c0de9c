// The OpenMP instantiation of the simulation for the cubic spline, and the backend's factory.
#define MW_BACKEND_OPENMP
#include "simulation/backend_simulation.hpp"
#include "simulation/factory.hpp"

namespace mw {

BackendInfo openmp_backend_info() {
    return BackendInfo{"openmp", true, true, openmp_backend::DeviceContext().description(),
                       openmp_backend::kPrefersNeighborLists};
}

void set_host_threads(int threads) { openmp_backend::set_host_threads(threads); }

std::unique_ptr<Simulation> create_openmp_simulation(const SimulationSetup& setup, int threads) {
    return openmp_backend::make_simulation(setup, threads);
}

}  // namespace mw

MW_BACKEND_BEGIN
std::unique_ptr<Simulation> make_cubic_spline_simulation(const SimulationSetup& setup, int threads) {
    return std::make_unique<BackendSimulation<CubicSpline3D>>(setup, threads);
}
MW_BACKEND_END
