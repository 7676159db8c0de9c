// Linked when the CUDA backend was not compiled: the program still answers what it has.
#include "simulation/factory.hpp"

namespace mw {
// prefers_neighbor_lists: the compiled backend's default (grid gathers), so that `info --backend
// cuda` estimates the GPU layout on any build.
BackendInfo cuda_backend_info() {
    return BackendInfo{"cuda", false, false, "not compiled (no CUDA compiler at configure time)", false};
}
std::unique_ptr<Simulation> create_cuda_simulation(const SimulationSetup&) {
    throw DeviceError("this build has no CUDA backend (configure with a CUDA compiler, MELTWATER_CUDA=ON)");
}
}  // namespace mw
