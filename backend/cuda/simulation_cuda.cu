// The CUDA instantiation of the algorithms, and its factory.
#define MW_BACKEND_CUDA
#include "algorithms/time_step.hpp"
#include "backend/backend_registry.hpp"

namespace mw {

BackendInfo cuda_backend_info() {
    const bool available = cuda_backend::backend_available();
    return BackendInfo{"cuda", true, available, available ? cuda_backend::device_description() : "compiled, but no CUDA device found",
                       cuda_backend::kPrefersNeighborLists};
}

std::unique_ptr<Simulation> create_cuda_simulation(const SimulationSetup& setup) {
    if (!cuda_backend::backend_available()) throw DeviceError("the CUDA backend was requested but no CUDA device was found");
    // The command line adds the scene's particle count and memory estimate to a DeviceError.
    return std::make_unique<cuda_backend::BackendSimulation>(setup);
}

}  // namespace mw
