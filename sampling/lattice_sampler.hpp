// IBPs: the lattice points (spacing r0, anchored as lattice.hpp explains) inside the mesh, with
// their integer lattice coordinates and one-ring (26-neighbour) connectivity for LSM regions.
#pragma once
#include <array>
#include <vector>

#include "sampling/inside_outside.hpp"
#include "sampling/lattice.hpp"
#include "sampling/mesh.hpp"

namespace mw {

struct InnerParticles {
    LatticeGrid grid;                             // the lattice the IBPs live on
    std::vector<Vec3d> positions;                 // rest positions
    std::vector<std::array<int, 3>> lattice;      // integer coordinates (i, j, k) on grid
    // One-ring neighbours in CSR form: the IBPs among the 26 lattice neighbours of IBP p are
    // neighbor_indices[neighbor_offsets[p] .. neighbor_offsets[p+1]), in increasing index order,
    // p itself excluded. An IBP with 26 of them is fully interior.
    std::vector<int> neighbor_offsets;
    std::vector<int> neighbor_indices;
    InsideOutsideResult classification;  // diagnostics (the inside flags are cleared to save memory)
    std::size_t count() const { return positions.size(); }
};

InnerParticles sample_inner(const TriangleMesh& mesh, double spacing, const InsideOutsideOptions& options = {});

}  // namespace mw
