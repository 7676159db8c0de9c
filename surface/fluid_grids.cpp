#include "surface/fluid_grids.hpp"

#include <algorithm>

#include <openvdb/io/Stream.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/LevelSetRebuild.h>

#include "surface/color_grid.hpp"

namespace mw {

namespace {
openvdb::math::Transform::Ptr node_transform(const SurfaceNodes& nodes) {
    openvdb::math::Transform::Ptr transform = openvdb::math::Transform::createLinearTransform(double(nodes.spacing));
    transform->postTranslate(openvdb::Vec3d(double(nodes.origin.x), double(nodes.origin.y), double(nodes.origin.z)));
    return transform;
}
}  // namespace

std::size_t write_fluid_grids(std::ostream& out, const SurfaceNodes& nodes, const std::vector<Real>& color, double iso) {
    openvdb::initialize();  // idempotent; the grid types must be registered before writing
    // Half a band of three voxels each side: what OpenVDB's level-set tools expect.
    constexpr float kHalfWidth = 3.0f;
    const double voxel = nodes.count() > 0 ? double(nodes.spacing) : 1.0;
    openvdb::FloatGrid::Ptr surface;
    openvdb::FloatGrid::Ptr density = openvdb::FloatGrid::create(0.0f);
    if (nodes.count() > 0) {
        // The rebuild meshes φ = iso - c at 0 and measures each voxel's distance to that mesh.
        const openvdb::FloatGrid::Ptr phi = color_level_grid(nodes, color, iso);
        surface = openvdb::tools::levelSetRebuild(*phi, 0.0f, kHalfWidth);
        std::vector<float> clamped(color.size());
        std::transform(color.begin(), color.end(), clamped.begin(),
                       [](Real c) { return std::clamp(float(c), 0.0f, 1.0f); });
        const openvdb::CoordBBox box(openvdb::Coord(0, 0, 0),
                                     openvdb::Coord(nodes.dims[0] - 1, nodes.dims[1] - 1, nodes.dims[2] - 1));
        openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, clamped.data());
        openvdb::tools::copyFromDense(dense, *density, 0.0f);
        density->setTransform(node_transform(nodes));
    } else {
        surface = openvdb::createLevelSet<openvdb::FloatGrid>(voxel, kHalfWidth);
        density->setTransform(openvdb::math::Transform::createLinearTransform(voxel));
    }
    surface->setName("surface");
    surface->setGridClass(openvdb::GRID_LEVEL_SET);
    density->setName("density");
    density->setGridClass(openvdb::GRID_FOG_VOLUME);
    openvdb::GridPtrVec grids{surface, density};
    openvdb::io::Stream(out).write(grids);
    return std::size_t(surface->activeVoxelCount());
}

}  // namespace mw
