// The CUDA instantiation of the simulation, for both kernels in 2D and 3D, and the backend's factory.
//
// All four are instantiated in this one translation unit, unlike OpenMP's two files. nvcc
// gives each translation unit its own copy (in an anonymous namespace) of the function pointers
// behind an extended __host__ __device__ lambda, and a lambda written in a non-template function
// (build_slot_map, fill_cell_ranges, ...) has the same type in every unit, so the linker keeps one
// unit's parallel_for<that lambda> while the lambda object may be made in the other: its copy is
// then called through a null pointer (a Wendland C2 scene with solids, compiled in a unit of its
// own, crashed so at its first such launch unless a cubic spline simulation had run before it in
// the process). tests/cuda_lambda_units.sh keeps any two CUDA units from sharing such a lambda.
#define MW_BACKEND_CUDA
#include "simulation/backend_simulation.hpp"
#include "simulation/factory.hpp"

namespace mw {

BackendInfo cuda_backend_info() {
    const std::string why_not = cuda_backend::unavailable_reason();
    const bool available = why_not.empty();
    return BackendInfo{"cuda", true, available,
                       available ? cuda_backend::DeviceContext(0).description() : "compiled, but " + why_not,
                       cuda_backend::kPrefersNeighborLists};
}

std::unique_ptr<Simulation> create_cuda_simulation(const SimulationSetup& setup) {
    const std::string why_not = cuda_backend::unavailable_reason();
    if (!why_not.empty()) throw DeviceError("the CUDA backend was requested but is unusable: " + why_not);
    // The command line adds the scene's particle count and memory estimate to a DeviceError.
    return cuda_backend::make_simulation(setup, 0);
}

}  // namespace mw

MW_BACKEND_BEGIN
std::unique_ptr<Simulation> make_cubic_spline_simulation(const SimulationSetup& setup, int threads) {
    return std::make_unique<BackendSimulation<CubicSpline3D>>(setup, threads);
}
std::unique_ptr<Simulation> make_wendland_c2_simulation(const SimulationSetup& setup, int threads) {
    return std::make_unique<BackendSimulation<WendlandC2_3D>>(setup, threads);
}
std::unique_ptr<Simulation> make_cubic_spline_2d_simulation(const SimulationSetup& setup, int threads) {
    return std::make_unique<BackendSimulation<CubicSpline2D>>(setup, threads);
}
std::unique_ptr<Simulation> make_wendland_c2_2d_simulation(const SimulationSetup& setup, int threads) {
    return std::make_unique<BackendSimulation<WendlandC2_2D>>(setup, threads);
}
MW_BACKEND_END
