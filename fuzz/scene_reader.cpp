// Fuzz target: the scene reader with --set overrides (apps/scene.hpp). The input is the scene's
// JSON text, then, after each NUL byte, one override ("key.path=value"), as `--set` gives them.
// Every input is either a scene or one InputError; anything else (a crash, another exception, a
// sanitizer report) is a finding.
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "apps/scene.hpp"
#include "common/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string input(reinterpret_cast<const char*>(data), size);
    std::vector<std::string> parts;
    for (std::size_t start = 0;;) {
        const std::size_t end = input.find('\0', start);
        parts.push_back(input.substr(start, end == std::string::npos ? std::string::npos : end - start));
        if (end == std::string::npos) break;
        start = end + 1;
    }
    const std::vector<std::string> overrides(parts.begin() + 1, parts.end());
    try {
        const mw::Scene scene = mw::parse_scene_text(parts.front(), "fuzz.json", overrides);
        // What `run` and `info` ask of a scene before building it.
        (void)scene.writes_frames();
        (void)scene.kernel_warning();
        (void)scene.largest_heat_diffusivity();
    } catch (const mw::InputError&) {
    }
    return 0;
}
