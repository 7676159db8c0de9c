// The OpenMP instantiation of the algorithms, and its factory.
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
    return std::make_unique<openmp_backend::BackendSimulation>(setup);
}

}  // namespace mw
