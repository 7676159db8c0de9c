// Binary PLY (little-endian, version 1.0) output, the format Blender's and Houdini's importers
// read: a point cloud with named per-point properties, or a triangle mesh. Written atomically.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "algorithms/vec3.hpp"
#include "apps/vtu_writer.hpp"

namespace mw {

// Points as vertices x, y, z (float), then each array as properties of the vertex: a scalar under
// its own name, a 3-vector as NAME_x, NAME_y, NAME_z (float32, int32 or uint8 as the array holds).
void write_ply_points(const std::string& path, const std::vector<Vec3>& points, const std::vector<VtuArray>& arrays,
                      const std::string& comment);

// A triangle mesh: vertices x, y, z (float) and faces as lists of three vertex indices; an
// outline (every triangle an edge (a, b, a), sampling/outline.hpp: the 2D fluid's contour) as
// edge elements (vertex1, vertex2) instead, as PLY readers take a curve.
void write_ply_mesh(const std::string& path, const std::vector<std::array<double, 3>>& vertices,
                    const std::vector<std::array<int, 3>>& triangles, const std::string& comment);

}  // namespace mw
