// Error types shared by every layer. Each carries one line that names the problem; the command
// line prints it and exits non-zero.
#pragma once
#include <cstdio>
#include <stdexcept>
#include <string>

namespace mw {
// Messages quote what the user wrote (keys, names, paths). A control character in it, NUL
// included (it would cut the C string that what() returns), is written as an escape, so that the
// message stays one whole line and sends no escape codes to a terminal.
inline std::string printable(const std::string& text) {
    std::string out;
    out.reserve(text.size());
    for (const char c : text) {
        const unsigned char u = static_cast<unsigned char>(c);
        if (u >= 0x20 && u != 0x7f) {
            out += c;
        } else if (u == '\n') {
            out += "\\n";
        } else {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\x%02x", u);
            out += escaped;
        }
    }
    return out;
}

// Bad user input: a missing file, malformed JSON, an unknown key, an out-of-range value, a broken mesh.
struct InputError : std::runtime_error {
    explicit InputError(const std::string& what) : std::runtime_error(printable(what)) {}
};
// The device cannot do what was asked (out of memory, no GPU, launch failure).
struct DeviceError : std::runtime_error {
    explicit DeviceError(const std::string& what) : std::runtime_error(printable(what)) {}
};
// The simulation itself failed (NaN/inf found); the message names the step and the particle.
struct SimulationError : std::runtime_error {
    explicit SimulationError(const std::string& what) : std::runtime_error(printable(what)) {}
};
}  // namespace mw
