#include "sampling/obj_loader.hpp"

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <tiny_obj_loader.h>

#include "backend/errors.hpp"

namespace mw {

namespace {

std::string first_line(const std::string& s) {
    std::string line = s.substr(0, s.find('\n'));
    while (!line.empty() && (line.back() == '\r' || line.back() == ' ')) line.pop_back();
    return line;
}

TriangleMesh from_reader(const tinyobj::ObjReader& reader, const std::string& source, bool require_volume) {
    if (!reader.Valid()) {
        const std::string err = first_line(reader.Error());
        throw InputError(source + ": cannot parse OBJ" + (err.empty() ? std::string() : " (" + err + ")"));
    }
    const tinyobj::attrib_t& attrib = reader.GetAttrib();
    TriangleMesh mesh;
    mesh.source = source;
    const std::size_t nv = attrib.vertices.size() / 3;
    mesh.vertices.resize(nv);
    for (std::size_t i = 0; i < nv; ++i)
        mesh.vertices[i] = Vec3d(attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]);
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        const auto& idx = shape.mesh.indices;
        std::size_t offset = 0;
        for (std::size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
            const int n = shape.mesh.num_face_vertices[f];
            // After triangulation every face has 3 corners; a face with fewer is malformed input.
            if (n == 3)
                mesh.triangles.push_back({idx[offset].vertex_index, idx[offset + 1].vertex_index, idx[offset + 2].vertex_index});
            else if (n > 3)  // tinyobjloader leaves some faces untriangulated: fan them
                for (int k = 1; k + 1 < n; ++k)
                    mesh.triangles.push_back(
                        {idx[offset].vertex_index, idx[offset + k].vertex_index, idx[offset + k + 1].vertex_index});
            offset += static_cast<std::size_t>(n);
        }
    }
    validate_mesh(mesh, require_volume);
    return mesh;
}

// tinyobjloader's number parser reads "nan" and "inf" as 0, so non-finite vertices are caught
// here, on the text, with the line number.
void check_vertex_lines(const std::string& text, const std::string& source) {
    std::size_t line_no = 0, vertex_no = 0, pos = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string::npos) end = text.size();
        ++line_no;
        std::size_t p = pos;
        while (p < end && (text[p] == ' ' || text[p] == '\t')) ++p;
        if (p + 1 < end && text[p] == 'v' && (text[p + 1] == ' ' || text[p + 1] == '\t')) {
            ++vertex_no;
            const std::string line = text.substr(p + 2, end - p - 2);
            const char* c = line.c_str();
            for (int k = 0; k < 3; ++k) {
                char* after = nullptr;
                const double x = std::strtod(c, &after);
                if (after == c || !std::isfinite(x)) {
                    std::ostringstream msg;
                    std::string shown = line;
                    while (!shown.empty() && (shown.back() == '\r' || shown.back() == ' ')) shown.pop_back();
                    msg << source << ": vertex " << vertex_no << " is not finite (line " << line_no << ": 'v " << shown << "')";
                    throw InputError(msg.str());
                }
                c = after;
            }
        }
        pos = end + 1;
    }
}

tinyobj::ObjReaderConfig config() {
    tinyobj::ObjReaderConfig c;
    c.triangulate = true;
    c.vertex_color = false;
    return c;
}

}  // namespace

TriangleMesh load_obj(const std::string& path, bool require_volume) {
    std::error_code ec;
    if (!std::filesystem::exists(path, ec)) throw InputError(path + ": mesh file does not exist");
    if (!std::filesystem::is_regular_file(path, ec)) throw InputError(path + ": not a regular file");
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw InputError(path + ": mesh file cannot be read");
    std::ostringstream text;
    text << probe.rdbuf();
    // Parse from text so that a missing .mtl next to the OBJ is never an error.
    return parse_obj(text.str(), path, require_volume);
}

TriangleMesh parse_obj(const std::string& text, const std::string& source, bool require_volume) {
    check_vertex_lines(text, source);
    tinyobj::ObjReader reader;
    reader.ParseFromString(text, std::string(), config());
    return from_reader(reader, source, require_volume);
}

}  // namespace mw
