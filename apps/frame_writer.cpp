#include "apps/frame_writer.hpp"

#include <algorithm>
#include <array>
#include <cstdio>
#include <filesystem>
#include <ostream>

#include "apps/atomic_file.hpp"
#include "apps/ply_writer.hpp"
#include "apps/vtu_writer.hpp"
#include "sampling/outline.hpp"
#include "surface/fluid_grids.hpp"

namespace mw {

namespace {
// The numbered files of a frame: prefix, extension.
// (object_NAME_NNNNN.obj is matched on its own: a name may hold anything.)
const std::array<std::pair<const char*, const char*>, 6> kNumberedFrameFiles{{{"particles_", ".vtu"},
                                                                           {"particles_", ".ply"},
                                                                           {"surface_", ".obj"},
                                                                           {"surface_", ".ply"},
                                                                           {"fluid_", ".vdb"},
                                                                           {"preview_", ".png"}}};
constexpr const char* kStaticStem = "static_boundary";

std::string numbered(const char* prefix, int index, const char* extension) {
    char name[64];
    std::snprintf(name, sizeof name, "%s%05d%s", prefix, index, extension);
    return name;
}

// An OBJ file, atomically: a comment line, the vertices and the triangles (1-based in the file);
// with `polyline`, one line element through every vertex in order (a rod: Blender and Houdini
// read it as a curve's edges). A 2D object's outline edges (a, b, a) are line elements "l a b".
void write_obj(const std::string& path, const std::string& comment, const std::vector<std::array<double, 3>>& vertices,
               const std::vector<std::array<int, 3>>& triangles, bool polyline = false) {
    write_file_atomically(path, [&](std::ostream& out) {
        out << "# " << comment << "\n";
        char line[128];
        for (const auto& x : vertices) {
            std::snprintf(line, sizeof line, "v %.7g %.7g %.7g\n", x[0], x[1], x[2]);
            out << line;
        }
        for (const auto& t : triangles) {
            if (is_outline_edge(t))
                std::snprintf(line, sizeof line, "l %d %d\n", t[0] + 1, t[1] + 1);
            else
                std::snprintf(line, sizeof line, "f %d %d %d\n", t[0] + 1, t[1] + 1, t[2] + 1);
            out << line;
        }
        if (polyline) {
            out << "l";
            for (std::size_t v = 1; v <= vertices.size(); ++v) out << ' ' << v;
            out << "\n";
        }
    });
}

template <class T>
std::vector<T> gather(const std::vector<T>& all, const std::vector<std::size_t>& shown) {
    std::vector<T> out(shown.size());
    for (std::size_t k = 0; k < shown.size(); ++k) out[k] = all[shown[k]];
    return out;
}

std::vector<float> gather_floats(const std::vector<Real>& all, const std::vector<std::size_t>& shown) {
    std::vector<float> out(shown.size());
    for (std::size_t k = 0; k < shown.size(); ++k) out[k] = float(all[shown[k]]);
    return out;
}
}  // namespace

int frame_file_number(const std::string& name) {
    const std::size_t digits = 5;
    for (const auto& [prefix, extension] : kNumberedFrameFiles) {
        const std::string p = prefix, e = extension;
        if (name.size() != p.size() + digits + e.size() || name.rfind(p, 0) != 0 ||
            name.compare(name.size() - e.size(), e.size(), e) != 0)
            continue;
        int number = 0;
        for (std::size_t k = p.size(); k < p.size() + digits; ++k) {
            if (name[k] < '0' || name[k] > '9') return -1;
            number = number * 10 + (name[k] - '0');
        }
        return number;
    }
    // object_NAME_NNNNN.obj: the object's name may hold anything before the last '_'.
    const std::string e = ".obj";
    if (name.rfind("object_", 0) == 0 && name.size() > 7 + digits + 1 + e.size() &&
        name.compare(name.size() - e.size(), e.size(), e) == 0 && name[name.size() - e.size() - digits - 1] == '_') {
        int number = 0;
        for (std::size_t k = name.size() - e.size() - digits; k < name.size() - e.size(); ++k) {
            if (name[k] < '0' || name[k] > '9') return -1;
            number = number * 10 + (name[k] - '0');
        }
        return number;
    }
    return -1;
}

bool is_frame_file(const std::string& name) {
    return frame_file_number(name) >= 0 || name == "particles.pvd" || name == std::string(kStaticStem) + ".vtu" ||
           name == std::string(kStaticStem) + ".ply";
}

FrameWriter::FrameWriter(const std::string& frames_dir, const FrameFormats& formats)
    : frames_dir_(frames_dir), formats_(formats) {
    make_directories(frames_dir_);
}

void FrameWriter::write_particles(const std::string& stem, const HostParticles& p, const std::vector<std::size_t>& shown,
                                  const std::string& comment) const {
    std::vector<Vec3> position = gather(p.position, shown);
    std::vector<std::int32_t> id(shown.size());
    for (std::size_t k = 0; k < shown.size(); ++k) id[k] = std::int32_t(shown[k]);
    std::vector<VtuArray> arrays;
    arrays.push_back(VtuArray::vector3("velocity", gather(p.velocity, shown)));
    arrays.push_back(VtuArray::scalar("density", gather_floats(p.density, shown)));
    arrays.push_back(VtuArray::scalar("pressure", gather_floats(p.pressure, shown)));
    arrays.push_back(VtuArray::uint8("type", gather(p.type, shown)));
    arrays.push_back(VtuArray::int32("object", gather(p.object, shown)));
    arrays.push_back(VtuArray::int32("id", std::move(id)));
    if (!p.temperature.empty()) arrays.push_back(VtuArray::scalar("temperature", gather_floats(p.temperature, shown)));
    if (formats_.vtu) write_vtu(frames_dir_ + "/" + stem + ".vtu", position, arrays);
    if (formats_.ply) write_ply_points(frames_dir_ + "/" + stem + ".ply", position, arrays, comment);
}

std::string FrameWriter::write(int index, const HostParticles& p, double time) {
    std::string path;
    if (formats_.particles()) {
        // Pending particles (an emitter's, not released yet) are not in the scene; static boundary
        // particles never move and go to their own file once.
        std::vector<std::size_t> moving, fixed;
        for (std::size_t i = 0; i < p.type.size(); ++i) {
            if (p.type[i] == kPending) continue;
            (p.type[i] == kStaticBoundary ? fixed : moving).push_back(i);
        }
        if (!static_written_) {
            has_static_ = !fixed.empty();
            if (has_static_) write_particles(kStaticStem, p, fixed, "meltwater static boundary particles");
            static_written_ = true;
        }
        const std::string stem = numbered("particles_", index, "");
        char comment[96];
        std::snprintf(comment, sizeof comment, "meltwater particles, frame %d, t = %.9g s", index, time);
        write_particles(stem, p, moving, comment);
        path = frames_dir_ + "/" + stem + (formats_.vtu ? ".vtu" : ".ply");
        if (formats_.vtu) {
            collection_.emplace_back(time, stem + ".vtu");
            write_collection();
        }
    }
    write_objects(index, p);  // the objects' GPs by their scene index, in the whole list
    ++written_;
    return path;
}

void FrameWriter::keep_earlier(const std::vector<double>& frame_times) {
    collection_.clear();
    for (std::size_t k = 0; k < frame_times.size(); ++k) {
        const std::string name = numbered("particles_", int(k), ".vtu");
        if (std::filesystem::exists(frames_dir_ + "/" + name)) collection_.emplace_back(frame_times[k], name);
    }
    if (formats_.vtu) write_collection();
}

void FrameWriter::write_collection() const {
    write_file_atomically(frames_dir_ + "/particles.pvd", [&](std::ostream& out) {
        out << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\">\n  <Collection>\n";
        char line[200];
        for (const auto& [t, file] : collection_) {
            std::snprintf(line, sizeof line, "    <DataSet timestep=\"%.9g\" part=\"0\" file=\"%s\"/>\n", t, file.c_str());
            out << line;
            // Part 1 of every time: the same static boundary file (ParaView shows the parts together).
            if (has_static_) {
                std::snprintf(line, sizeof line, "    <DataSet timestep=\"%.9g\" part=\"1\" file=\"%s.vtu\"/>\n", t,
                              kStaticStem);
                out << line;
            }
        }
        out << "  </Collection>\n</VTKFile>\n";
    });
}

void FrameWriter::write_surface(int index, const TriangleMesh& mesh) const {
    std::vector<std::array<double, 3>> vertices(mesh.vertices.size());
    for (std::size_t v = 0; v < vertices.size(); ++v)
        vertices[v] = {mesh.vertices[v].x(), mesh.vertices[v].y(), mesh.vertices[v].z()};
    const std::string comment = "meltwater fluid surface, frame " + std::to_string(index) + ": " +
                                std::to_string(mesh.vertices.size()) + " vertices, " +
                                std::to_string(mesh.triangles.size()) + " triangles";
    if (formats_.surface) write_obj(frames_dir_ + "/" + numbered("surface_", index, ".obj"), comment, vertices, mesh.triangles);
    if (formats_.surface && formats_.ply)
        write_ply_mesh(frames_dir_ + "/" + numbered("surface_", index, ".ply"), vertices, mesh.triangles, comment);
}

void FrameWriter::write_fluid_grids(int index, const FluidSurfacer::Field& field) const {
    write_file_atomically(frames_dir_ + "/" + numbered("fluid_", index, ".vdb"), [&](std::ostream& out) {
        mw::write_fluid_grids(out, field.nodes, field.color, field.iso);
    });
}

std::string FrameWriter::write_preview(int index, const Image& picture) const {
    const std::string path = frames_dir_ + "/" + numbered("preview_", index, ".png");
    const std::string png = encode_png(picture);
    write_file_atomically(path, [&](std::ostream& out) { out.write(png.data(), std::streamsize(png.size())); });
    return path;
}

std::vector<std::array<double, 3>> object_vertices(const SolidSetup& o, const HostParticles& p) {
    const bool moving = o.kind != SolidKind::kStatic;
    std::vector<std::array<double, 3>> vertices(moving ? o.gp.size() : o.rest_vertices.size());
    for (std::size_t g = 0; g < vertices.size(); ++g) {
        const Vec3 x = moving ? p.position[o.gp[g]] : o.rest_vertices[g];
        vertices[g] = {double(x.x), double(x.y), double(x.z)};
    }
    return vertices;
}

void FrameWriter::write_objects(int index, const HostParticles& p) const {
    for (const SolidSetup& o : objects_) {
        const bool rod = o.kind == SolidKind::kRod;
        if (o.triangles.empty() && !rod) continue;  // a static box: no mesh
        write_obj(frames_dir_ + "/object_" + o.name + numbered("_", index, ".obj"),
                  "meltwater object " + o.name + ", frame " + std::to_string(index), object_vertices(o, p), o.triangles,
                  rod);
    }
}

}  // namespace mw
