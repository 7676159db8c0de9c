// Fuzz target: the checkpoint reader (apps/checkpoint_file.hpp) and the scene it carries, which a
// resumed run reads next. Every input is a checkpoint or one InputError.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "apps/checkpoint_file.hpp"
#include "apps/scene.hpp"
#include "common/errors.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::vector<unsigned char> file(data, data + size);
    try {
        const mw::Checkpoint checkpoint = mw::parse_checkpoint(file, "checkpoint 'fuzz.mwc'");
        (void)mw::resolve_scene(checkpoint.scene, "checkpoint 'fuzz.mwc'");
    } catch (const mw::InputError&) {
    }
    return 0;
}
