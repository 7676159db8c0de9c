// The CUDA instantiation of the algorithms for the cubic spline, and the backend's factory.
#define MW_BACKEND_CUDA
#include "algorithms/time_step.hpp"
#include "backend/backend_registry.hpp"

namespace mw {

BackendInfo cuda_backend_info() {
    const std::string why_not = cuda_backend::unavailable_reason();
    const bool available = why_not.empty();
    return BackendInfo{"cuda", true, available,
                       available ? cuda_backend::device_description() : "compiled, but " + why_not,
                       cuda_backend::kPrefersNeighborLists};
}

std::unique_ptr<Simulation> create_cuda_simulation(const SimulationSetup& setup) {
    const std::string why_not = cuda_backend::unavailable_reason();
    if (!why_not.empty()) throw DeviceError("the CUDA backend was requested but is unusable: " + why_not);
    // The command line adds the scene's particle count and memory estimate to a DeviceError.
    return cuda_backend::make_simulation(setup);
}

}  // namespace mw

MW_BACKEND_BEGIN
std::unique_ptr<Simulation> make_cubic_spline_simulation(const SimulationSetup& setup) {
    return std::make_unique<BackendSimulation<CubicSpline3D>>(setup);
}
MW_BACKEND_END
