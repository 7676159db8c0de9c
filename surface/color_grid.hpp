// The colour field as an OpenVDB grid: φ = iso - c on the field's nodes (negative inside the
// fluid), a level set in the grid's class so that OpenVDB's tools treat it as one. What the mesher
// (fluid_surface.cpp) and the .vdb frames (fluid_grids.cpp) both start from.
#pragma once
#include <vector>

#include <openvdb/openvdb.h>

#include "simulation/simulation.hpp"

namespace mw {
openvdb::FloatGrid::Ptr color_level_grid(const SurfaceNodes& nodes, const std::vector<Real>& color, double iso);
}  // namespace mw
