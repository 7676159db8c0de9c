#include "surface/fluid_surface.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <mutex>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/global_control.h>

#include "backend/errors.hpp"

namespace mw {

SurfaceNodes surface_nodes_around_fluid(const HostParticles& particles, Vec3 domain_min, Vec3 domain_max,
                                        Real support_radius, Real spacing, std::size_t max_nodes) {
    SurfaceNodes nodes;
    nodes.spacing = spacing;
    const Real inf = std::numeric_limits<Real>::infinity();
    Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
    bool any = false;
    for (std::size_t i = 0; i < particles.position.size(); ++i) {
        if (particles.type[i] != kFluid) continue;
        const Vec3 x = particles.position[i];
        const Real h = support_radius;
        // Written so that a NaN position fails it too.
        if (!(x.x >= domain_min.x - h && x.x <= domain_max.x + h && x.y >= domain_min.y - h &&
              x.y <= domain_max.y + h && x.z >= domain_min.z - h && x.z <= domain_max.z + h))
            continue;
        lo = Vec3{std::min(lo.x, x.x), std::min(lo.y, x.y), std::min(lo.z, x.z)};
        hi = Vec3{std::max(hi.x, x.x), std::max(hi.y, x.y), std::max(hi.z, x.z)};
        any = true;
    }
    if (!any) return nodes;
    // One support radius and one node beyond the outermost particles: the field is 0 there, so
    // the mesh closes inside the box. And a quarter node more: fluid on a lattice whose spacing
    // the node spacing divides (every scene's start) would otherwise have its faces, r0/2 outside
    // the last layer, exactly on a plane of nodes, where φ is 0 give or take rounding and the
    // mesher cuts the face into slivers (2.7 times the triangles on the default dam break's frame 0).
    const Real margin = support_radius + Real(1.25) * spacing;
    nodes.origin = Vec3{lo.x - margin, lo.y - margin, lo.z - margin};
    const Real extent[3] = {hi.x - lo.x + 2 * margin, hi.y - lo.y + 2 * margin, hi.z - lo.z + 2 * margin};
    double count = 1;
    for (int a = 0; a < 3; ++a) {
        const double d = std::ceil(double(extent[a]) / double(spacing)) + 1;
        count *= d;
        nodes.dims[a] = count <= double(max_nodes) ? static_cast<int>(d) : 0;
    }
    if (count > double(max_nodes)) {
        char text[200];
        std::snprintf(text, sizeof text,
                      "surface: the fluid spans %.3g x %.3g x %.3g m, %.3g nodes at %.3g m, more than %zu; raise "
                      "output.surface.voxel",
                      double(hi.x - lo.x), double(hi.y - lo.y), double(hi.z - lo.z), count, double(spacing), max_nodes);
        throw InputError(text);
    }
    return nodes;
}

SurfaceMesh mesh_color_field(const SurfaceNodes& nodes, const std::vector<float>& color, double iso, int threads) {
    SurfaceMesh mesh;
    if (nodes.count() == 0) return mesh;
    if (color.size() != nodes.count()) throw std::logic_error("mesh_color_field: field and nodes differ in size");
    static std::once_flag initialised;
    std::call_once(initialised, [] { openvdb::initialize(); });
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

    // A level set's sign: φ = iso - c, negative inside the fluid; nodes with no fluid within a
    // support radius (c = 0) are the background and stay inactive.
    std::vector<float> phi(color.size());
    const float iso_f = static_cast<float>(iso);
    std::transform(color.begin(), color.end(), phi.begin(), [iso_f](float c) { return iso_f - c; });
    const openvdb::CoordBBox box(openvdb::Coord(0, 0, 0),
                                 openvdb::Coord(nodes.dims[0] - 1, nodes.dims[1] - 1, nodes.dims[2] - 1));
    // LayoutXYZ: x varies fastest, as in the field.
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, phi.data());
    openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(iso_f);
    // A level set (negative inside): the mesher's winding depends on the grid's class.
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    grid->setTransform(openvdb::math::Transform::createLinearTransform(double(nodes.spacing)));
    grid->transform().postTranslate(
        openvdb::Vec3d(double(nodes.origin.x), double(nodes.origin.y), double(nodes.origin.z)));
    openvdb::tools::copyFromDense(dense, *grid, 0.0f);

    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*grid, points, triangles, quads, 0.0, 0.0);
    mesh.vertices.reserve(points.size());
    for (const auto& p : points) mesh.vertices.push_back(Vec3{Real(p.x()), Real(p.y()), Real(p.z())});
    // The mesher winds its polygons clockwise seen from the positive side of φ (outside): reversed
    // here, so that the triangles face out of the fluid.
    mesh.triangles.reserve(triangles.size() + 2 * quads.size());
    for (const auto& t : triangles) mesh.triangles.push_back({int(t[0]), int(t[2]), int(t[1])});
    for (const auto& q : quads) {
        mesh.triangles.push_back({int(q[0]), int(q[2]), int(q[1])});
        mesh.triangles.push_back({int(q[0]), int(q[3]), int(q[2])});
    }
    return mesh;
}

double enclosed_volume(const SurfaceMesh& mesh) {
    double volume = 0;
    for (const auto& t : mesh.triangles) {
        const Vec3 a = mesh.vertices[t[0]], b = mesh.vertices[t[1]], c = mesh.vertices[t[2]];
        volume += (double(a.x) * (double(b.y) * c.z - double(b.z) * c.y) +
                   double(a.y) * (double(b.z) * c.x - double(b.x) * c.z) +
                   double(a.z) * (double(b.x) * c.y - double(b.y) * c.x)) /
                  6.0;
    }
    return volume;
}

}  // namespace mw
