#include "apps/vtu_writer.hpp"

#include <ostream>
#include <sstream>

#include "apps/atomic_file.hpp"

namespace mw {

VtuArray VtuArray::scalar(std::string name, std::vector<float> values) {
    VtuArray a;
    a.name = std::move(name);
    a.floats = std::move(values);
    return a;
}
VtuArray VtuArray::vector3(std::string name, const std::vector<Vec3>& values) {
    VtuArray a;
    a.name = std::move(name);
    a.components = 3;
    a.floats.reserve(values.size() * 3);
    for (const Vec3& v : values) {
        a.floats.push_back(static_cast<float>(v.x));
        a.floats.push_back(static_cast<float>(v.y));
        a.floats.push_back(static_cast<float>(v.z));
    }
    return a;
}
VtuArray VtuArray::int32(std::string name, std::vector<std::int32_t> values) {
    VtuArray a;
    a.name = std::move(name);
    a.ints = std::move(values);
    return a;
}
VtuArray VtuArray::uint8(std::string name, std::vector<std::uint8_t> values) {
    VtuArray a;
    a.name = std::move(name);
    a.bytes = std::move(values);
    return a;
}

namespace {
// One block of the appended section: a UInt64 byte count, then the raw little-endian bytes.
struct Block {
    const void* data;
    std::uint64_t bytes;
};
const char* vtk_type(const VtuArray& a) {
    if (!a.floats.empty()) return "Float32";
    if (!a.ints.empty()) return "Int32";
    return "UInt8";
}
}  // namespace

void write_vtu(const std::string& path, const std::vector<Vec3>& points, const std::vector<VtuArray>& arrays) {
    const std::uint64_t n = points.size();
    std::vector<float> coords;
    coords.reserve(n * 3);
    for (const Vec3& p : points) {
        coords.push_back(static_cast<float>(p.x));
        coords.push_back(static_cast<float>(p.y));
        coords.push_back(static_cast<float>(p.z));
    }
    std::vector<std::int64_t> connectivity(n), offsets(n);
    std::vector<std::uint8_t> cell_types(n, 1);  // VTK_VERTEX
    for (std::uint64_t i = 0; i < n; ++i) {
        connectivity[i] = static_cast<std::int64_t>(i);
        offsets[i] = static_cast<std::int64_t>(i + 1);
    }

    std::vector<Block> blocks;
    std::ostringstream xml;
    std::uint64_t offset = 0;
    auto add_block = [&](const void* data, std::uint64_t bytes) {
        blocks.push_back({data, bytes});
        const std::uint64_t at = offset;
        offset += sizeof(std::uint64_t) + bytes;
        return at;
    };
    xml << "<?xml version=\"1.0\"?>\n"
        << "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" header_type=\"UInt64\">\n"
        << "  <UnstructuredGrid>\n"
        << "    <Piece NumberOfPoints=\"" << n << "\" NumberOfCells=\"" << n << "\">\n"
        << "      <PointData>\n";
    for (const VtuArray& a : arrays) {
        std::uint64_t bytes = a.floats.size() * 4 + a.ints.size() * 4 + a.bytes.size();
        const void* data = !a.floats.empty() ? static_cast<const void*>(a.floats.data())
                           : !a.ints.empty() ? static_cast<const void*>(a.ints.data())
                                             : static_cast<const void*>(a.bytes.data());
        xml << "        <DataArray type=\"" << vtk_type(a) << "\" Name=\"" << a.name << "\" NumberOfComponents=\""
            << a.components << "\" format=\"appended\" offset=\"" << add_block(data, bytes) << "\"/>\n";
    }
    xml << "      </PointData>\n      <Points>\n"
        << "        <DataArray type=\"Float32\" NumberOfComponents=\"3\" format=\"appended\" offset=\""
        << add_block(coords.data(), coords.size() * 4) << "\"/>\n"
        << "      </Points>\n      <Cells>\n"
        << "        <DataArray type=\"Int64\" Name=\"connectivity\" format=\"appended\" offset=\""
        << add_block(connectivity.data(), n * 8) << "\"/>\n"
        << "        <DataArray type=\"Int64\" Name=\"offsets\" format=\"appended\" offset=\""
        << add_block(offsets.data(), n * 8) << "\"/>\n"
        << "        <DataArray type=\"UInt8\" Name=\"types\" format=\"appended\" offset=\""
        << add_block(cell_types.data(), n) << "\"/>\n"
        << "      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n"
        << "  <AppendedData encoding=\"raw\">\n   _";

    write_file_atomically(path, [&](std::ostream& out) {
        const std::string head = xml.str();
        out.write(head.data(), static_cast<std::streamsize>(head.size()));
        for (const Block& b : blocks) {
            out.write(reinterpret_cast<const char*>(&b.bytes), sizeof b.bytes);
            out.write(static_cast<const char*>(b.data), static_cast<std::streamsize>(b.bytes));
        }
        out << "\n  </AppendedData>\n</VTKFile>\n";
    });
}

}  // namespace mw
