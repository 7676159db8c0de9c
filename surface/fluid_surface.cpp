#include "surface/fluid_surface.hpp"
#include "surface/color_grid.hpp"
#include "surface/contour.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/VolumeToMesh.h>
#include <tbb/global_control.h>


namespace mw {

namespace {
// One support radius and one node beyond the outermost particles: the field is 0 there, so the
// mesh closes inside the box. And a quarter node more: fluid on a lattice whose spacing the node
// spacing divides (every scene's start) would otherwise have its faces, r0/2 outside the last
// layer, exactly on a plane of nodes, where φ is 0 give or take rounding and the mesher cuts the
// face into slivers (2.7 times the triangles on the default dam break's frame 0).
Real node_margin(Real support_radius, Real spacing) { return support_radius + Real(1.25) * spacing; }
}  // namespace

std::array<double, 3> surface_node_dims(Vec3 lo, Vec3 hi, Real support_radius, Real spacing, int dimensions) {
    const double margin = double(node_margin(support_radius, spacing));
    const double extent[3] = {double(hi.x - lo.x), double(hi.y - lo.y), double(hi.z - lo.z)};
    std::array<double, 3> dims{1, 1, 1};
    for (int a = 0; a < dimensions; ++a) dims[a] = std::ceil((extent[a] + 2 * margin) / double(spacing)) + 1;
    return dims;
}

double most_surface_nodes(const SimulationParams& params, Real spacing) {
    const Real h = params.fluid.support_radius;
    const std::array<double, 3> dims = surface_node_dims(params.domain_min - Vec3{h, h, h},
                                                         params.domain_max + Vec3{h, h, h}, h, spacing, params.dimensions);
    return dims[0] * dims[1] * dims[2];
}

SurfaceNodes surface_nodes_around_fluid(const HostParticles& particles, Vec3 domain_min, Vec3 domain_max,
                                        Real support_radius, Real spacing, int dimensions) {
    SurfaceNodes nodes;
    nodes.spacing = spacing;
    const Real inf = std::numeric_limits<Real>::infinity(), h = support_radius;
    Vec3 lo{inf, inf, inf}, hi{-inf, -inf, -inf};
    bool any = false;
    for (std::size_t i = 0; i < particles.position.size(); ++i) {
        if (particles.type[i] != kFluid) continue;
        const Vec3 x = particles.position[i];
        // Written so that a NaN position fails it too.
        if (!(x.x >= domain_min.x - h && x.x <= domain_max.x + h && x.y >= domain_min.y - h &&
              x.y <= domain_max.y + h && x.z >= domain_min.z - h && x.z <= domain_max.z + h))
            continue;
        lo = Vec3{std::min(lo.x, x.x), std::min(lo.y, x.y), std::min(lo.z, x.z)};
        hi = Vec3{std::max(hi.x, x.x), std::max(hi.y, x.y), std::max(hi.z, x.z)};
        any = true;
    }
    if (!any) return nodes;
    const std::array<double, 3> dims = surface_node_dims(lo, hi, support_radius, spacing, dimensions);
    if (dims[0] * dims[1] * dims[2] > double(kMaxSurfaceNodes))
        throw std::logic_error("surface_nodes_around_fluid: more nodes than resolve_scene's check allows");
    const Real margin = node_margin(support_radius, spacing);
    nodes.origin = Vec3{lo.x - margin, lo.y - margin, dimensions == 3 ? lo.z - margin : Real(0)};
    for (int a = 0; a < 3; ++a) nodes.dims[a] = static_cast<int>(dims[a]);
    return nodes;
}

openvdb::FloatGrid::Ptr color_level_grid(const SurfaceNodes& nodes, const std::vector<Real>& color, double iso) {
    static std::once_flag initialised;
    std::call_once(initialised, [] { openvdb::initialize(); });
    // A level set's sign: φ = iso - c, negative inside the fluid; nodes with no fluid within a
    // support radius (c = 0) are the background and stay inactive.
    std::vector<float> phi(color.size());
    const float iso_f = static_cast<float>(iso);
    std::transform(color.begin(), color.end(), phi.begin(), [iso_f](Real c) { return iso_f - float(c); });
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
    return grid;
}

TriangleMesh mesh_color_field(const SurfaceNodes& nodes, const std::vector<Real>& color, double iso, int threads) {
    TriangleMesh mesh;
    mesh.source = "the fluid's surface";
    if (nodes.count() == 0) return mesh;
    if (color.size() != nodes.count()) throw std::logic_error("mesh_color_field: field and nodes differ in size");
    std::unique_ptr<tbb::global_control> limit;
    if (threads > 0)
        limit = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);

    const openvdb::FloatGrid::Ptr grid = color_level_grid(nodes, color, iso);
    std::vector<openvdb::Vec3s> points;
    std::vector<openvdb::Vec3I> triangles;
    std::vector<openvdb::Vec4I> quads;
    openvdb::tools::volumeToMesh(*grid, points, triangles, quads, 0.0, 0.0);
    mesh.vertices.reserve(points.size());
    for (const auto& p : points) mesh.vertices.emplace_back(double(p.x()), double(p.y()), double(p.z()));
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

FluidSurfacer::FluidSurfacer(const SimulationParams& params, double voxel_in_r0, int threads)
    : domain_min_(params.domain_min),
      domain_max_(params.domain_max),
      support_radius_(params.fluid.support_radius),
      spacing_(Real(voxel_in_r0) * params.fluid.spacing),
      dimensions_(params.dimensions),
      threads_(threads) {}

namespace {
using SurfaceClock = std::chrono::steady_clock;
double ms_since(SurfaceClock::time_point t) {
    return std::chrono::duration<double, std::milli>(SurfaceClock::now() - t).count();
}
}  // namespace

const FluidSurfacer::Field& FluidSurfacer::field(Simulation& sim, const HostParticles& particles) {
    const auto start = SurfaceClock::now();
    field_.nodes = surface_nodes_around_fluid(particles, domain_min_, domain_max_, support_radius_, spacing_, dimensions_);
    field_.iso = 0;
    field_.color.clear();
    if (field_.nodes.count() > 0) sim.fluid_color_field(field_.nodes, field_.color, field_.iso);
    field_.ms = ms_since(start);
    return field_;
}

FluidSurfacer::Surface FluidSurfacer::build(Simulation& sim, const HostParticles& particles) {
    Surface out;
    const auto start = SurfaceClock::now();
    field(sim, particles);
    out.field_ms = field_.ms;
    out.mesh = dimensions_ == 2 ? contour_color_field(field_.nodes, field_.color, field_.iso)
                                : mesh_color_field(field_.nodes, field_.color, field_.iso, threads_);
    out.ms = ms_since(start);
    return out;
}

}  // namespace mw
