// What the program was built with, and the factories that create a simulation on each backend.
// Host-only; defined in simulation/instantiate_openmp.cpp, simulation/instantiate_cuda.cu (or
// simulation/cuda_absent.cpp).
#pragma once
#include <memory>
#include <string>

#include "simulation/simulation.hpp"
#include "common/errors.hpp"

namespace mw {
struct BackendInfo {
    std::string name;
    bool compiled = false;
    bool available = false;     // compiled and a device is usable now
    std::string description;    // device found, or why not
    bool prefers_neighbor_lists = false;  // what neighbors.lists "auto" means on this backend
};
BackendInfo openmp_backend_info();
BackendInfo cuda_backend_info();
std::unique_ptr<Simulation> create_openmp_simulation(const SimulationSetup& setup, int threads);
// Host threads for what runs before a simulation exists (sampling objects); 0 keeps the default.
// Starts the thread team at once: when the system cannot create the threads, libgomp ends the
// process, and that had better happen before any output is made.
void set_host_threads(int threads);
std::unique_ptr<Simulation> create_cuda_simulation(const SimulationSetup& setup);
}  // namespace mw
