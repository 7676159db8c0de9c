// Error types shared by every layer. Each carries one line that names the problem; the command
// line prints it and exits non-zero.
#pragma once
#include <stdexcept>
#include <string>

namespace mw {
// Bad user input: a missing file, malformed JSON, an unknown key, an out-of-range value, a broken mesh.
struct InputError : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// The device cannot do what was asked (out of memory, no GPU, launch failure).
struct DeviceError : std::runtime_error {
    using std::runtime_error::runtime_error;
};
// The simulation itself failed (NaN/inf found); the message names the step and the particle.
struct SimulationError : std::runtime_error {
    using std::runtime_error::runtime_error;
};
}  // namespace mw
