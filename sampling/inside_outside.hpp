// Inside/outside classification with Embree ray casts, robust on scans with holes.
//
// Method: signed crossing counts along lattice lines, averaged over directions. A ray from p in
// direction d crosses an outward-oriented closed surface with signs s = sign(n·d) (+1 leaving,
// -1 entering); their sum is the winding number of the surface around p, 1 inside and 0 outside,
// whatever d is. For an open surface (the bunny's base) one direction can be wrong, but the
// average over directions of that sum is a Monte-Carlo estimate of the generalized winding
// number (Jacobson et al. 2013), which is what "inside" means for a mesh with holes: near 1 in
// the body, near 0 outside, about 1/2 across a hole. We cast ONE ray per lattice line, collect
// every crossing on it (an Embree intersection filter that records and rejects each hit), and
// read both senses, +d and -d, for every lattice point on the line: 2 samples per line family,
// 3 families (axes) for closed meshes, 13 (axes, face and body diagonals: every lattice line
// direction through one-ring neighbours) for open ones. A point is inside when the mean exceeds
// 1/2.
//
// Robustness: hits on shared edges and vertices are merged (hits closer than a tiny distance
// along the ray form one group whose signs are summed and clamped to [-1, 1]), so a ray through an
// edge counts one crossing and a ray grazing a silhouette counts none; Embree is built with
// RTC_SCENE_FLAG_ROBUST so rays through edges do not slip between triangles. For a closed,
// consistently oriented mesh every direction gives the exact answer and the result is exact up
// to points lying on the surface itself. Meshes with inconsistent orientation fall back to
// crossing parity.
//
// Open meshes: the vote is an estimate; at the few points where it lies near 1/2 (across a hole)
// the generalized winding number itself decides (FastWindingNumber, exact near 1/2), so the
// result is "winding number > 1/2" everywhere, which is the body of the scan with its holes
// closed by the minimal-area-like surface the winding number defines.
#pragma once
#include <cstdint>
#include <memory>
#include <vector>

#include "sampling/lattice.hpp"
#include "sampling/mesh.hpp"

namespace mw {

struct InsideOutsideOptions {
    // Line families: 0 = automatic (3 for closed meshes, 13 for open ones), or 3, 7 or 13.
    int directions = 0;
    // Open meshes only: points whose vote lies within this of 1/2 are decided by the generalized
    // winding number itself (winding_number.hpp: fast, and exact near 1/2). 0 disables.
    double refine_band = 0.3;
};

struct InsideOutsideResult {
    std::vector<std::uint8_t> inside;  // per lattice point (LatticeGrid::index order)
    int directions_used = 0;           // line families (each read in both senses)
    std::size_t rays = 0;
    std::size_t ambiguous = 0;  // points where the direction samples disagree (0 for closed meshes)
    bool parity = false;        // crossing parity was used (inconsistently oriented mesh)
    double build_seconds = 0;   // Embree BVH build
    std::size_t refined = 0;    // points decided by the winding number (open meshes)
    double refine_seconds = 0;
};

// Classifies every point of the lattice. The mesh should be outward oriented (sample_solid flips
// meshes with negative signed volume first). Throws InputError when a lattice line would start
// more than 1e6 mesh sizes from the mesh (a grid far from it, or a spacing far larger than it).
InsideOutsideResult classify_lattice(const TriangleMesh& mesh, const LatticeGrid& grid,
                                     const InsideOutsideOptions& options = {});

// Classifies arbitrary points the same way (rays in `directions` families through each point).
std::vector<std::uint8_t> classify_points(const TriangleMesh& mesh, const std::vector<Vec3d>& points,
                                          int directions = 13, double refine_band = 0.3);

// Exact generalized winding number of the mesh around p (sum of signed solid angles / 4π);
// O(triangles) per point: for checks and tests, not for bulk classification.
double winding_number(const TriangleMesh& mesh, const Vec3d& p);

}  // namespace mw
