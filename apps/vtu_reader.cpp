#include "apps/vtu_reader.hpp"

#include <cstring>
#include <fstream>
#include <sstream>

#include "common/errors.hpp"

namespace mw {

namespace {
// The value of attribute `name` in the XML tag `tag` ("" when absent).
std::string attribute(const std::string& tag, const std::string& name) {
    const std::string key = " " + name + "=\"";
    const std::size_t at = tag.find(key);
    if (at == std::string::npos) return "";
    const std::size_t start = at + key.size(), end = tag.find('"', start);
    return end == std::string::npos ? "" : tag.substr(start, end - start);
}

struct ArrayTag {
    std::string type, name;
    int components = 1;
    std::uint64_t offset = 0;
    bool is_points = false;
};
}  // namespace

const VtuArray* VtuFrame::find(const std::string& name) const {
    for (const VtuArray& a : arrays)
        if (a.name == name) return &a;
    return nullptr;
}

VtuFrame read_vtu(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError(path + ": cannot be read");
    std::stringstream buffer;
    buffer << in.rdbuf();
    const std::string text = buffer.str();
    const auto refuse = [&path](const std::string& why) { return InputError(path + ": " + why); };
    const std::size_t appended = text.find("<AppendedData encoding=\"raw\">");
    const std::size_t data_start = appended == std::string::npos ? appended : text.find('_', appended);
    if (text.find("header_type=\"UInt64\"") == std::string::npos || data_start == std::string::npos)
        throw refuse("not a VTU frame in the layout meltwater writes (appended raw data, UInt64 headers)");
    const std::string head = text.substr(0, appended);
    const std::size_t piece = head.find("<Piece ");
    if (piece == std::string::npos) throw refuse("no <Piece>");
    const std::string points_text = attribute(head.substr(piece, head.find('>', piece) - piece), "NumberOfPoints");
    char* end = nullptr;
    const unsigned long long n = std::strtoull(points_text.c_str(), &end, 10);
    if (points_text.empty() || *end != '\0') throw refuse("a bad NumberOfPoints");

    std::vector<ArrayTag> tags;
    const std::size_t points_at = head.find("<Points>");
    for (std::size_t at = head.find("<DataArray "); at != std::string::npos; at = head.find("<DataArray ", at + 1)) {
        const std::string tag = head.substr(at, head.find('>', at) - at);
        ArrayTag a;
        a.type = attribute(tag, "type"), a.name = attribute(tag, "Name");
        const std::string components = attribute(tag, "NumberOfComponents");
        a.components = components.empty() ? 1 : std::atoi(components.c_str());
        a.offset = std::strtoull(attribute(tag, "offset").c_str(), nullptr, 10);
        a.is_points = points_at != std::string::npos && at > points_at && a.name.empty();
        if (a.components < 1 || a.components > 3) throw refuse("an array of " + components + " components");
        tags.push_back(a);
    }
    const std::size_t base = data_start + 1;
    VtuFrame frame;
    for (const ArrayTag& a : tags) {
        if (a.name == "connectivity" || a.name == "offsets" || a.name == "types") continue;
        const std::size_t size = a.type == "UInt8" ? 1 : 4;
        if (!(a.type == "Float32" || a.type == "Int32" || a.type == "UInt8"))
            throw refuse("an array of type " + a.type);
        const std::uint64_t count = n * std::uint64_t(a.components), bytes = count * size;
        std::uint64_t header = 0;
        if (base + a.offset + 8 + bytes > text.size()) throw refuse("ends before its data (truncated?)");
        std::memcpy(&header, text.data() + base + a.offset, 8);
        if (header != bytes) throw refuse("array '" + a.name + "' holds " + std::to_string(header) + " bytes, not " +
                                          std::to_string(bytes));
        const char* data = text.data() + base + a.offset + 8;
        if (a.is_points) {
            std::vector<float> xyz(count);
            if (bytes > 0) std::memcpy(xyz.data(), data, bytes);  // a frame of no particle: no data to copy
            frame.points.resize(n);
            for (std::uint64_t i = 0; i < n; ++i) frame.points[i] = Vec3{Real(xyz[3 * i]), Real(xyz[3 * i + 1]), Real(xyz[3 * i + 2])};
            continue;
        }
        VtuArray out;
        out.name = a.name;
        out.components = a.components;
        // An empty array's data() may be null, which memcpy must not be given even for 0 bytes.
        if (a.type == "Float32") out.floats.resize(count);
        else if (a.type == "Int32") out.ints.resize(count);
        else out.bytes.resize(count);
        void* to = a.type == "Float32" ? static_cast<void*>(out.floats.data())
                   : a.type == "Int32" ? static_cast<void*>(out.ints.data())
                                       : static_cast<void*>(out.bytes.data());
        if (bytes > 0) std::memcpy(to, data, bytes);
        frame.arrays.push_back(std::move(out));
    }
    if (frame.points.size() != n) throw refuse("no points array");
    return frame;
}

}  // namespace mw
