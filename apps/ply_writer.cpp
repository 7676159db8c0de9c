#include "apps/ply_writer.hpp"

#include <cstdint>
#include <cstring>
#include <ostream>

#include "apps/atomic_file.hpp"
#include "sampling/outline.hpp"

namespace mw {

namespace {
static_assert(sizeof(float) == 4, "PLY float is 32-bit");

// PLY's name of the array's element type.
const char* ply_type(const VtuArray& a) {
    if (!a.floats.empty()) return "float";
    if (!a.ints.empty()) return "int";
    return "uchar";
}

// One comment line: PLY's header is line-based, so the comment must hold no line break.
std::string one_line(std::string text) {
    for (char& c : text)
        if (c == '\n' || c == '\r') c = ' ';
    return text;
}

// Appends the raw little-endian bytes of `value` (x86 and every CUDA host are little-endian).
template <class T>
void put(std::string& bytes, T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    bytes.append(raw, sizeof(T));
}
}  // namespace

void write_ply_points(const std::string& path, const std::vector<Vec3>& points, const std::vector<VtuArray>& arrays,
                      const std::string& comment) {
    std::string header = "ply\nformat binary_little_endian 1.0\ncomment " + one_line(comment) + "\nelement vertex " +
                         std::to_string(points.size()) + "\nproperty float x\nproperty float y\nproperty float z\n";
    for (const VtuArray& a : arrays) {
        if (a.components == 1) {
            header += std::string("property ") + ply_type(a) + " " + a.name + "\n";
        } else {
            for (const char* axis : {"_x", "_y", "_z"}) header += std::string("property ") + ply_type(a) + " " + a.name + axis + "\n";
        }
    }
    header += "end_header\n";
    std::size_t per_point = 12;
    for (const VtuArray& a : arrays)
        per_point += std::size_t(a.components) * (a.floats.empty() && a.ints.empty() ? 1 : 4);
    write_file_atomically(path, [&](std::ostream& out) {
        out << header;
        // Interleaved rows, a block of points at a time: one write per block, not per value.
        constexpr std::size_t kBlock = 8192;
        std::string bytes;
        bytes.reserve(kBlock * per_point);
        for (std::size_t first = 0; first < points.size(); first += kBlock) {
            bytes.clear();
            const std::size_t last = std::min(points.size(), first + kBlock);
            for (std::size_t i = first; i < last; ++i) {
                put(bytes, float(points[i].x));
                put(bytes, float(points[i].y));
                put(bytes, float(points[i].z));
                for (const VtuArray& a : arrays)
                    for (int c = 0; c < a.components; ++c) {
                        const std::size_t k = i * std::size_t(a.components) + std::size_t(c);
                        if (!a.floats.empty()) put(bytes, a.floats[k]);
                        else if (!a.ints.empty()) put(bytes, a.ints[k]);
                        else put(bytes, a.bytes[k]);
                    }
            }
            out.write(bytes.data(), std::streamsize(bytes.size()));
        }
    });
}

void write_ply_mesh(const std::string& path, const std::vector<std::array<double, 3>>& vertices,
                    const std::vector<std::array<int, 3>>& triangles, const std::string& comment) {
    const bool edges = is_outline(triangles);
    const std::string elements = edges ? "\nelement edge " + std::to_string(triangles.size()) +
                                             "\nproperty int vertex1\nproperty int vertex2"
                                       : "\nelement face " + std::to_string(triangles.size()) +
                                             "\nproperty list uchar int vertex_indices";
    const std::string header = "ply\nformat binary_little_endian 1.0\ncomment " + one_line(comment) +
                               "\nelement vertex " + std::to_string(vertices.size()) +
                               "\nproperty float x\nproperty float y\nproperty float z" + elements + "\nend_header\n";
    write_file_atomically(path, [&](std::ostream& out) {
        out << header;
        std::string bytes;
        bytes.reserve(vertices.size() * 12 + triangles.size() * 13);
        for (const auto& v : vertices)
            for (double x : v) put(bytes, float(x));
        for (const auto& t : triangles) {
            if (edges) {
                put(bytes, std::int32_t(t[0]));
                put(bytes, std::int32_t(t[1]));
                continue;
            }
            put(bytes, std::uint8_t(3));
            for (int index : t) put(bytes, std::int32_t(index));
        }
        out.write(bytes.data(), std::streamsize(bytes.size()));
    });
}

}  // namespace mw
