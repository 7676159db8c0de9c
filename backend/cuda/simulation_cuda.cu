// The CUDA instantiation of the algorithms, for both kernels, and the backend's factory.
//
// Both kernels are instantiated in this one translation unit, unlike OpenMP's two files. nvcc
// gives each translation unit its own copy (in an anonymous namespace) of the function pointers
// behind an extended __host__ __device__ lambda, and a lambda written in a non-template function
// (build_slot_map, fill_cell_ranges, ...) has the same type in every unit, so the linker keeps one
// unit's parallel_for<that lambda> while the lambda object may be made in the other: its copy is
// then called through a null pointer. With the Wendland C2 simulation in a file of its own, a
// Wendland scene with solids crashed at its first such launch on an H200 (2026-12-04), unless a
// cubic spline simulation had run earlier in the same process. tests/cuda_lambda_units.sh keeps
// any two CUDA units from sharing such a lambda.
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
std::unique_ptr<Simulation> make_wendland_c2_simulation(const SimulationSetup& setup) {
    return std::make_unique<BackendSimulation<WendlandC2_3D>>(setup);
}
MW_BACKEND_END
