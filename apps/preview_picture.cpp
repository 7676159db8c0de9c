#include "apps/preview_picture.hpp"

#include "apps/frame_writer.hpp"
#include "sampling/outline.hpp"

#include <cmath>
#include <cstdio>

namespace mw {

namespace {
PreviewMesh preview_mesh(const std::vector<std::array<double, 3>>& vertices,
                         const std::vector<std::array<int, 3>>& triangles) {
    PreviewMesh m;
    m.vertices.reserve(vertices.size() * 3);
    for (const auto& v : vertices)
        for (double x : v) m.vertices.push_back(float(x));
    m.triangles.reserve(triangles.size() * 3);
    for (const auto& t : triangles)
        for (int index : t) m.triangles.push_back(std::uint32_t(index));
    return m;
}

const char* field_title(PreviewField field) {
    switch (field) {
        case PreviewField::kSpeed: return "speed, m/s";
        case PreviewField::kPressure: return "pressure, Pa";
        case PreviewField::kDensity: return "density, kg/m3";
        case PreviewField::kTemperature: return "temperature, C";
    }
    return "";
}
}  // namespace

PreviewMesh rod_tube(const std::vector<std::array<double, 3>>& line, double radius) {
    constexpr int kSides = 6;
    std::vector<std::array<double, 3>> vertices;
    std::vector<std::array<int, 3>> triangles;
    const auto at = [&](std::size_t k) { return Vec3d(line[k][0], line[k][1], line[k][2]); };
    for (std::size_t k = 0; k < line.size(); ++k) {
        const Vec3d before = k > 0 ? at(k) - at(k - 1) : at(k + 1) - at(k);
        const Vec3d after = k + 1 < line.size() ? at(k + 1) - at(k) : before;
        Vec3d t = before.normalized() + after.normalized();
        if (!(t.norm() > 0)) t = after;
        t.normalize();
        const Vec3d u = t.unitOrthogonal(), w = t.cross(u);
        for (int s = 0; s < kSides; ++s) {
            const double a = 2 * M_PI * s / kSides;
            const Vec3d x = at(k) + radius * (std::cos(a) * u + std::sin(a) * w);
            vertices.push_back({x.x(), x.y(), x.z()});
        }
        if (k == 0) continue;
        const int ring = int(k) * kSides, last = ring - kSides;
        for (int s = 0; s < kSides; ++s) {
            const int s1 = (s + 1) % kSides;
            triangles.push_back({last + s, last + s1, ring + s1});
            triangles.push_back({last + s, ring + s1, ring + s});
        }
    }
    return solid_preview_mesh(vertices, triangles);
}

PreviewMesh solid_preview_mesh(const std::vector<std::array<double, 3>>& vertices,
                               const std::vector<std::array<int, 3>>& triangles) {
    PreviewMesh m = preview_mesh(vertices, triangles);
    m.colour = {176, 150, 120};  // a warm grey apart from the fluid's blues and greens
    return m;
}

PreviewMesh surface_preview_mesh(const TriangleMesh& surface, double line_width) {
    if (is_outline(surface)) {
        PreviewMesh band;
        band.colour = {20, 70, 170};
        band.smooth = false;
        // In front of the particles' discs (r0/2 deep) by a line width, a quad per edge.
        const double z = 2 * line_width;
        for (const auto& t : surface.triangles) {
            const Vec3d& a = surface.vertices[std::size_t(t[0])];
            const Vec3d& b = surface.vertices[std::size_t(t[1])];
            const Vec3d d = b - a;
            const double length = std::hypot(d.x(), d.y());
            if (!(length > 0)) continue;
            const double nx = -d.y() / length * 0.5 * line_width, ny = d.x() / length * 0.5 * line_width;
            const auto first = std::uint32_t(band.vertices.size() / 3);
            for (const auto& [px, py] : {std::pair{a.x() - nx, a.y() - ny}, std::pair{b.x() - nx, b.y() - ny},
                                         std::pair{b.x() + nx, b.y() + ny}, std::pair{a.x() + nx, a.y() + ny}})
                band.vertices.insert(band.vertices.end(), {float(px), float(py), float(z)});
            // Counter-clockwise seen from +z, where the head-on camera stands.
            band.triangles.insert(band.triangles.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
        }
        return band;
    }
    std::vector<std::array<double, 3>> vertices(surface.vertices.size());
    for (std::size_t v = 0; v < vertices.size(); ++v)
        vertices[v] = {surface.vertices[v].x(), surface.vertices[v].y(), surface.vertices[v].z()};
    PreviewMesh m = preview_mesh(vertices, surface.triangles);
    // Translucent: the particles inside, coloured by the field, still show through.
    m.colour = {70, 130, 210};
    m.opacity = 0.45f;
    return m;
}

bool drawn_as_mesh(SolidKind kind, bool melts, int dimensions) {
    return kind == SolidKind::kRod || (!melts && dimensions == 3);
}

std::vector<PreviewMesh> object_preview_meshes(const std::vector<SolidSetup>& solids, const HostParticles& p,
                                               int dimensions) {
    std::vector<PreviewMesh> meshes;
    for (const SolidSetup& o : solids) {
        if (!drawn_as_mesh(o.kind, o.melts(), dimensions)) continue;
        if (o.kind == SolidKind::kRod) {
            if (o.gp.size() > 1) meshes.push_back(rod_tube(object_vertices(o, p), 0.5 * double(o.spacing)));
            continue;
        }
        if (o.triangles.empty()) continue;  // a box: its particles show it
        meshes.push_back(solid_preview_mesh(object_vertices(o, p), o.triangles));
    }
    return meshes;
}

Image preview_picture(const Scene& scene, const HostParticles& p, std::vector<PreviewMesh> meshes, double time,
                      int index, double speed_scale) {
    PreviewFrame frame;
    const std::size_t n = p.position.size();
    frame.positions.reserve(3 * n);
    frame.values.reserve(n);
    frame.kinds.reserve(n);
    const PreviewField field = scene.preview.field;
    for (std::size_t i = 0; i < n; ++i) {
        const Vec3 x = p.position[i];
        frame.positions.insert(frame.positions.end(), {float(x.x), float(x.y), float(x.z)});
        // Walls' particles are boundary (not drawn); a mesh stands for its object's particles (the
        // solids' SBPs would poke through it); GPs are the meshes' vertices; pending particles are
        // not in the scene yet. Static boxes and melting objects have no mesh: their particles show.
        const std::uint8_t type = p.type[i];
        const std::int32_t object = p.object[i];
        const bool meshed = object >= 0 && std::size_t(object) < scene.objects.size() &&
                            drawn_as_mesh(scene.objects[object].kind, scene.objects[object].melts(), scene.params.dimensions);
        PreviewKind kind = PreviewKind::hidden;
        if (type == kFluid) kind = PreviewKind::fluid;
        else if (type == kStaticBoundary && object < 0) kind = PreviewKind::boundary;
        else if (type == kStaticBoundary || type == kSurfaceBoundary || type == kInnerBoundary)
            kind = meshed ? PreviewKind::hidden : PreviewKind::solid;
        frame.kinds.push_back(kind);
        double value = 0;
        switch (field) {
            case PreviewField::kSpeed: value = double(norm(p.velocity[i])); break;
            case PreviewField::kPressure: value = double(p.pressure[i]); break;
            case PreviewField::kDensity: value = double(p.density[i]); break;
            case PreviewField::kTemperature: value = p.temperature.empty() ? 0.0 : double(p.temperature[i]); break;
        }
        frame.values.push_back(float(value));
    }
    frame.particle_radius = 0.5 * double(scene.params.fluid.spacing);
    frame.field_name = field_title(field);
    if (field == PreviewField::kSpeed && speed_scale > 0) frame.field_range = std::array<double, 2>{0.0, speed_scale};
    frame.meshes = std::move(meshes);
    const Vec3 lo = scene.params.domain_min, hi = scene.params.domain_max;
    frame.domain = std::array<PreviewVec, 2>{PreviewVec{lo.x, lo.y, lo.z}, PreviewVec{hi.x, hi.y, hi.z}};
    char caption[128];
    std::snprintf(caption, sizeof caption, "%s  t = %.3f s  frame %d", scene.name.empty() ? "meltwater" : scene.name.c_str(),
                  time, index);
    frame.caption = caption;
    PreviewCamera camera;
    camera.eye = {scene.preview.eye.x, scene.preview.eye.y, scene.preview.eye.z};
    camera.target = {scene.preview.target.x, scene.preview.target.y, scene.preview.target.z};
    camera.fov_y_degrees = scene.preview.fov;
    PreviewStyle style;
    style.width = scene.preview.width;
    style.height = scene.preview.height;
    return render_preview(frame, camera, style);
}

}  // namespace mw
