// Fuzz target: the OBJ reader with its checks (sampling/obj_loader.hpp), as a scene's mesh file
// is read: as an open surface (a static object may be one) and, when that reads, as a closed one
// (a solid must be). Every input is a mesh or one InputError.
#include <cstddef>
#include <cstdint>
#include <string>

#include "common/errors.hpp"
#include "sampling/mesh.hpp"
#include "sampling/obj_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
    const std::string text(reinterpret_cast<const char*>(data), size);
    try {
        const mw::TriangleMesh mesh = mw::parse_obj(text, "fuzz.obj", false);
        mw::validate_mesh(mesh, true);
    } catch (const mw::InputError&) {
    }
    return 0;
}
