// The fluid of a frame as OpenVDB grids, for the .vdb frames that Houdini and Blender read:
//   "surface": a narrow-band signed distance level set in metres (negative inside), rebuilt by
//              OpenVDB from the colour field's iso-surface, the same surface as the OBJ meshes;
//   "density": the colour field itself, clamped to [0, 1], as a fog volume (1 inside fluid at
//              rest, falling to 0 one support radius outside it), what volume renderers shade.
// Both live on the colour field's nodes (output.surface.voxel r0 apart).
#pragma once
#include <ostream>
#include <vector>

#include "simulation/simulation.hpp"

namespace mw {
// Writes both grids, in OpenVDB's stream format (what openvdb::io::File and pyopenvdb read), to
// `out`. A frame without fluid (no nodes) writes both grids empty. Returns the level set's
// active voxels.
std::size_t write_fluid_grids(std::ostream& out, const SurfaceNodes& nodes, const std::vector<Real>& color, double iso);
}  // namespace mw
