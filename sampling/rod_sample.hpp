// A rod's centreline to particles (docs/rods.md): one line. The polyline is resampled at equal
// steps of at most r0 along its length; each sample is a shape-matching node (with its share of
// the length, and its two neighbours along the line, which the regions grow on), and the surface
// particles the fluid meets sit on the segments between nodes, two per segment. Host only.
#pragma once
#include <cstdint>
#include <vector>

#include "sampling/mesh.hpp"

namespace mw {

constexpr int kRodSamplesPerSegment = 2;  // SBPs per segment between two nodes

struct RodSample {
    std::vector<Vec3d> nodes;         // along the line, first to last
    std::vector<double> node_length;  // per node: half of each segment it ends
    std::vector<std::uint32_t> graph_offsets, graph_links;  // per node, its neighbours along the line (CSR)
    // Surface particles: on segment `segment` (nodes segment, segment + 1) at `fraction` of the way.
    std::vector<Vec3d> sbp;
    std::vector<std::uint32_t> sbp_segment;
    std::vector<double> sbp_fraction;
    double length = 0;  // m, along the polyline
};

// `line`: the centreline's vertices in order, no triangles (procedural "line", docs/rods.md).
// Refuses (InputError naming the mesh) a mesh with triangles, a repeated vertex, and a line too
// short for three nodes (a region needs a line of three to bend).
RodSample sample_rod(const TriangleMesh& line, double spacing);

}  // namespace mw
