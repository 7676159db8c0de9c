// VTK XML UnstructuredGrid (.vtu) output of a point cloud with named point-data arrays, in the
// appended raw binary encoding (compact and fast; ParaView and meshio read it).
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/vec3.hpp"

namespace mw {

struct VtuArray {
    std::string name;
    int components = 1;
    // Exactly one of these holds the data (components × points values).
    std::vector<float> floats;
    std::vector<std::int32_t> ints;
    std::vector<std::uint8_t> bytes;

    static VtuArray scalar(std::string name, std::vector<float> values);
    static VtuArray vector3(std::string name, const std::vector<Vec3>& values);
    static VtuArray int32(std::string name, std::vector<std::int32_t> values);
    static VtuArray uint8(std::string name, std::vector<std::uint8_t> values);
};

// Writes points (one VTK_VERTEX cell each) and arrays to `path`, atomically.
void write_vtu(const std::string& path, const std::vector<Vec3>& points, const std::vector<VtuArray>& arrays);

}  // namespace mw
