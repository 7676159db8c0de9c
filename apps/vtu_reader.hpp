// Reads back the VTU frames vtu_writer.hpp writes (appended raw binary, UInt64 block headers,
// Float32 / Int32 / UInt8 arrays), for `meltwater render`. Not a general VTK reader: a file in
// another layout is refused with an InputError naming it.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "apps/vtu_writer.hpp"

namespace mw {

struct VtuFrame {
    std::vector<Vec3> points;
    std::vector<VtuArray> arrays;
    // The array named `name`, or nullptr.
    const VtuArray* find(const std::string& name) const;
};

VtuFrame read_vtu(const std::string& path);

}  // namespace mw
