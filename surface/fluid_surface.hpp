// Surface reconstruction: the fluid's colour field (algorithms/surface_field.hpp) on a box of
// nodes, turned into a closed triangle mesh at its iso-value by OpenVDB's mesher (host only,
// at frame times). The field is the product's own (the SPH kernel, computed by the backend);
// the meshing is a well-kept library's.
#pragma once
#include <array>
#include <string>
#include <vector>

#include "algorithms/simulation.hpp"

namespace mw {

// The node box around the fluid particles among `particles` (type kFluid) that lie within one
// support radius of the domain [domain_min, domain_max] (fluid lost beyond is left out): their
// bounding box grown by one support radius and a node on each side, at `spacing`; no node at all
// (dims 0) without such fluid. Throws InputError when it would need more than `max_nodes` nodes.
SurfaceNodes surface_nodes_around_fluid(const HostParticles& particles, Vec3 domain_min, Vec3 domain_max,
                                        Real support_radius, Real spacing, std::size_t max_nodes);

// The most nodes a frame's field may take (a float each on the device and on the host, twice
// over on the host while meshing): 2^28, 1 GiB of floats.
constexpr std::size_t kMaxSurfaceNodes = std::size_t(1) << 28;

struct SurfaceMesh {
    std::vector<Vec3> vertices;
    std::vector<std::array<int, 3>> triangles;  // counter-clockwise seen from outside the fluid
};

// The level set c = iso of the colour field `color` at `nodes` (c above iso is fluid). `threads`:
// at most that many threads for the mesher (0: all).
SurfaceMesh mesh_color_field(const SurfaceNodes& nodes, const std::vector<float>& color, double iso, int threads);

// The signed volume a closed mesh encloses (positive when its triangles face outward), m³.
double enclosed_volume(const SurfaceMesh& mesh);

}  // namespace mw
