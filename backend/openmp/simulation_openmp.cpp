// The OpenMP instantiation of the algorithms for the cubic spline, and the backend's factory.
#define MW_BACKEND_OPENMP
#include "algorithms/time_step.hpp"
#include "backend/backend_registry.hpp"

namespace mw {

BackendInfo openmp_backend_info() {
    return BackendInfo{"openmp", true, true, openmp_backend::device_description(), openmp_backend::kPrefersNeighborLists};
}

void set_host_threads(int threads) {
    openmp_backend::set_threads(threads);
    openmp_backend::start_thread_team();
}

std::unique_ptr<Simulation> create_openmp_simulation(const SimulationSetup& setup, int threads) {
    openmp_backend::set_threads(threads);
    return openmp_backend::make_simulation(setup);
}

}  // namespace mw

MW_BACKEND_BEGIN
std::unique_ptr<Simulation> make_cubic_spline_simulation(const SimulationSetup& setup) {
    return std::make_unique<BackendSimulation<CubicSpline3D>>(setup);
}
MW_BACKEND_END
