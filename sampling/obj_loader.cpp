#include "sampling/obj_loader.hpp"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <vector>

#include <tiny_obj_loader.h>

#include "common/errors.hpp"

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
    // The reader drops invalid faces with only a warning; checked_obj_text should have refused
    // them already, and a face lost here would leave a hole, so any face warning is an error.
    std::istringstream warnings(reader.Warning());
    for (std::string warning; std::getline(warnings, warning);)
        if (warning.find("face") != std::string::npos || warning.find("Face") != std::string::npos ||
            warning.rfind("Vertex indices out of bounds", 0) == 0)
            throw InputError(source + ": invalid OBJ (" + first_line(warning) + ")");
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
            // checked_obj_text refuses faces with fewer than 3 corners; should one get here anyway
            // it is malformed input, never something to drop in silence.
            if (n < 3) {
                std::ostringstream msg;
                msg << source << ": face " << f + 1 << " of shape '" << shape.name << "' has " << n
                    << " corners, a face needs at least 3";
                throw InputError(msg.str());
            }
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

// One line of the OBJ text, for messages: its number and its content without the line break.
struct ObjLine {
    std::size_t number;
    std::string text;
    bool last_and_unterminated;  // the file ends inside this line: maybe truncated
};

std::string quoted(const ObjLine& line) {
    std::string shown = line.text;
    while (!shown.empty() && (shown.back() == '\r' || shown.back() == ' ' || shown.back() == '\t')) shown.pop_back();
    return "'" + shown + "'";
}

[[noreturn]] void reject_line(const std::string& source, const ObjLine& line, const std::string& problem) {
    std::ostringstream msg;
    msg << source << ": " << problem << " (line " << line.number << ": " << quoted(line) << ")";
    if (line.last_and_unterminated) msg << "; the file ends in this line without a line break: is it truncated?";
    throw InputError(msg.str());
}

// The whitespace-separated words of `text` after its first `from` characters.
std::vector<std::string> tokens_of(const std::string& text, std::size_t from) {
    std::vector<std::string> tokens;
    const char* blank = " \t\r";
    for (std::size_t start = text.find_first_not_of(blank, from); start != std::string::npos;) {
        const std::size_t stop = text.find_first_of(blank, start);
        tokens.push_back(text.substr(start, stop == std::string::npos ? std::string::npos : stop - start));
        start = stop == std::string::npos ? stop : text.find_first_not_of(blank, stop);
    }
    return tokens;
}

// Calls visit(line, kind) for every vertex ("v "), face ("f ") and polyline ("l ") line of the
// OBJ text, kind its first letter.
template <class Visit>
void for_each_element_line(const std::string& text, Visit&& visit) {
    std::size_t pos = 0, line_no = 0;
    while (pos < text.size()) {
        std::size_t end = text.find('\n', pos);
        const bool unterminated = end == std::string::npos;
        if (unterminated) end = text.size();
        ++line_no;
        std::size_t p = pos;
        while (p < end && (text[p] == ' ' || text[p] == '\t')) ++p;
        if (p + 1 < end && (text[p] == 'v' || text[p] == 'f' || text[p] == 'l') &&
            (text[p + 1] == ' ' || text[p + 1] == '\t'))
            visit(ObjLine{line_no, text.substr(p, end - p), unterminated}, text[p]);
        pos = end + 1;
    }
}

// The vertex index a face corner or a line point refers to ("v", "v/vt", "v//vn" or "v/vt/vn":
// the vertex index comes first), as written, checked against the `vertices` before it (a
// negative index counts back from there) and the file's `total_vertices`; `element` ("face 3",
// "the line") names it in the message. Read as long long, not int: an index beyond int (which the
// reader's atoi wraps) saturates and is reported as the number written.
long long checked_vertex_index(const std::string& corner, const std::string& element, long long vertices,
                               long long total_vertices, const std::string& source, const ObjLine& line) {
    const std::string token = corner.substr(0, corner.find('/'));
    char* after = nullptr;
    const long long index = std::strtoll(token.c_str(), &after, 10);
    const bool number = !token.empty() && after != token.c_str() && *after == '\0';
    if (number && index != 0 && index >= -vertices && index <= total_vertices) return index;
    std::ostringstream problem;
    problem << element;
    if (!number)
        problem << ": '" << corner << "' is not a vertex index";
    else if (index == 0)
        problem << " refers to vertex 0, but OBJ vertex indices start at 1";
    else if (index < 0)
        problem << " refers to vertex " << token << " (counted back from the end), but only " << vertices
                << " vertices precede it";
    else
        problem << " refers to vertex " << token << ", but the file has " << total_vertices << " vertices";
    reject_line(source, line, problem.str());
}

// tinyobjloader is lenient where a sampler must not be: it reads "nan", "inf" and missing or
// garbled coordinates as 0, drops faces with fewer than 3 corners or an index past the end with
// only a warning, and parses indices with atoi (so 99999999999 wraps to another vertex). Its number
// parser also overflows on exponents beyond ±2147483647 (and reads 1e-2147483649 as infinity),
// and it converts skin weights ("vw") to int with no range check. Vertex and face lines are
// therefore checked here first, on the text, so each problem is reported with its line number;
// and the reader is given only what was checked, written afresh: each vertex as "v x y z" with the
// values already read (printed so that they read back exactly), each face as "f" and its vertex
// indices. In a file without faces, its one polyline ("l", a rod's centreline) is checked the same
// way and returned in `polyline` (0-based vertex indices), not given to the reader. Every other line
// (normals, texture coordinates, groups, materials, skin weights, ...) the sampler does not use,
// and the reader never sees.
std::string checked_obj_text(const std::string& text, const std::string& source, std::vector<int>& polyline) {
    // Faces may use vertices defined after them, so positive indices are checked against the
    // file's total, counted first.
    long long total_vertices = 0, total_faces = 0;
    for_each_element_line(text, [&](const ObjLine&, char kind) {
        total_vertices += kind == 'v';
        total_faces += kind == 'f';
    });
    const double largest_parsed = double(std::numeric_limits<tinyobj::real_t>::max());
    long long vertices = 0, faces = 0, lines = 0;
    std::string checked;
    checked.reserve(text.size());
    char number_text[64];
    for_each_element_line(text, [&](const ObjLine& line, char kind) {
        const std::vector<std::string> tokens = tokens_of(line.text, 2);
        if (kind == 'l') {
            // In a file with faces the lines are a surface's stray edges: not read.
            if (total_faces > 0) return;
            if (++lines > 1)
                reject_line(source, line, "a second line (\"l\"); a rod is one line: join them into one");
            if (tokens.size() < 2) {
                std::ostringstream problem;
                problem << "the line has " << tokens.size() << " point" << (tokens.size() == 1 ? "" : "s")
                        << ", a line needs at least 2";
                reject_line(source, line, problem.str());
            }
            std::vector<bool> visited(static_cast<std::size_t>(total_vertices), false);
            for (const std::string& point : tokens) {
                const long long index = checked_vertex_index(point, "the line", vertices, total_vertices, source, line);
                const int at = int(index > 0 ? index - 1 : vertices + index);
                if (visited[static_cast<std::size_t>(at)]) {
                    std::ostringstream problem;
                    problem << "the line visits vertex " << at + 1 << " twice; a rod's line is open, each point once";
                    reject_line(source, line, problem.str());
                }
                visited[static_cast<std::size_t>(at)] = true;
                polyline.push_back(at);
            }
            return;
        }
        if (kind == 'v') {
            ++vertices;
            if (tokens.size() < 3) {
                std::ostringstream problem;
                problem << "vertex " << vertices << " has " << tokens.size() << " coordinate"
                        << (tokens.size() == 1 ? "" : "s") << ", a vertex needs x y z";
                reject_line(source, line, problem.str());
            }
            checked += 'v';
            for (int k = 0; k < 3; ++k) {
                const std::string& token = tokens[static_cast<std::size_t>(k)];
                char* after = nullptr;
                const double x = std::strtod(token.c_str(), &after);
                const bool number = after != token.c_str() && *after == '\0';
                if (number && std::isfinite(x) && std::abs(x) <= largest_parsed) {
                    std::snprintf(number_text, sizeof number_text, " %.*g",
                                  std::numeric_limits<tinyobj::real_t>::max_digits10,
                                  double(static_cast<tinyobj::real_t>(x)));
                    checked += number_text;
                    continue;
                }
                std::ostringstream problem;
                problem << "vertex " << vertices;
                if (!number)
                    problem << ": '" << token << "' is not a number";
                else if (!std::isfinite(x))
                    problem << " is not finite";
                else
                    problem << ": " << token << " is beyond the largest coordinate the OBJ reader holds (" << largest_parsed
                            << ")";
                reject_line(source, line, problem.str());
            }
            checked += '\n';
            return;
        }
        ++faces;
        if (tokens.size() < 3) {
            std::ostringstream problem;
            problem << "face " << faces << " has " << tokens.size() << " corner" << (tokens.size() == 1 ? "" : "s")
                    << ", a face needs at least 3";
            reject_line(source, line, problem.str());
        }
        checked += 'f';
        for (const std::string& corner : tokens)
            checked += ' ' + std::to_string(checked_vertex_index(corner, "face " + std::to_string(faces), vertices,
                                                                 total_vertices, source, line));
        checked += '\n';
    });
    return checked;
}

tinyobj::ObjReaderConfig config() {
    tinyobj::ObjReaderConfig c;
    c.triangulate = true;
    c.vertex_color = false;
    return c;
}

// A rod's centreline from an OBJ with one polyline ("l") and no faces: the reader's vertices (read
// as a surface's are) in the line's order, as a mesh of vertices and no triangles (as the
// procedural "line" is).
TriangleMesh polyline_mesh(const tinyobj::ObjReader& reader, const std::string& source, const std::vector<int>& polyline) {
    if (!reader.Valid()) throw InputError(source + ": cannot parse OBJ (" + first_line(reader.Error()) + ")");
    const std::vector<tinyobj::real_t>& v = reader.GetAttrib().vertices;
    TriangleMesh mesh;
    mesh.source = source;
    for (int k : polyline) {
        const Vec3d x(v[3 * std::size_t(k)], v[3 * std::size_t(k) + 1], v[3 * std::size_t(k) + 2]);
        if (x.cwiseAbs().maxCoeff() > kMaxCoordinate) {
            std::ostringstream msg;
            msg << source << ": point " << mesh.vertices.size() + 1
                << " of the line is out of range: coordinates must lie within +-" << kMaxCoordinate;
            throw InputError(msg.str());
        }
        mesh.vertices.push_back(x);
    }
    return mesh;
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

TriangleMesh load_obj_edges(const std::string& path) {
    std::ifstream probe(path, std::ios::binary);
    if (!probe) throw InputError(path + ": OBJ file cannot be read");
    std::ostringstream text;
    text << probe.rdbuf();
    tinyobj::ObjReader reader;
    reader.ParseFromString(text.str(), std::string(), config());
    if (!reader.Valid()) throw InputError(path + ": cannot parse OBJ (" + first_line(reader.Error()) + ")");
    const std::vector<tinyobj::real_t>& v = reader.GetAttrib().vertices;
    TriangleMesh outline;
    outline.source = path;
    for (std::size_t k = 0; k + 2 < v.size(); k += 3) outline.vertices.emplace_back(v[k], v[k + 1], v[k + 2]);
    for (const tinyobj::shape_t& shape : reader.GetShapes()) {
        if (!shape.mesh.indices.empty()) throw InputError(path + ": holds faces, not an outline's edges");
        std::size_t at = 0;
        for (const int points : shape.lines.num_line_vertices) {
            for (int p = 0; p + 1 < points; ++p) {
                const int a = shape.lines.indices[at + std::size_t(p)].vertex_index;
                const int b = shape.lines.indices[at + std::size_t(p) + 1].vertex_index;
                if (a < 0 || b < 0 || std::size_t(std::max(a, b)) >= outline.vertices.size())
                    throw InputError(path + ": a line names a vertex past the " + std::to_string(outline.vertices.size()) + " given");
                if (a != b) outline.triangles.push_back({a, b, a});
            }
            at += std::size_t(points);
        }
    }
    return outline;
}

TriangleMesh parse_obj(const std::string& text, const std::string& source, bool require_volume) {
    std::vector<int> polyline;
    const std::string checked = checked_obj_text(text, source, polyline);
    tinyobj::ObjReader reader;
    reader.ParseFromString(checked, std::string(), config());
    return polyline.empty() ? from_reader(reader, source, require_volume) : polyline_mesh(reader, source, polyline);
}

}  // namespace mw
