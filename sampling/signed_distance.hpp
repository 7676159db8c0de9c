// Signed distance to a triangle mesh, sampled on a regular grid: what the velocity–position
// correction reads to keep fluid out of a static mesh object (algorithms/wall_contact.hpp,
// algorithms/distance_field.hpp).
//
// Why a grid and not the object's particles: a static object never moves, so its distance can be
// computed once, exactly, from its mesh. The correction then knows the surface and its normal
// everywhere near it and inside it, at one trilinear lookup per particle, including a particle that
// a large step has carried past the object's surface particles (the particles' band, docs/method.md
// step 7, only reaches r0 into the solid).
//
// How: the sign comes from the inside/outside classification of the samplers (inside_outside.hpp:
// exact for closed meshes; for open ones, the generalized winding number above 1/2); the magnitude
// is the exact distance to the nearest triangle, found with Embree's closest-point query over the
// mesh's BVH and measured in double precision, at every node that may lie within the grid's margin
// of the surface. Nodes farther than that keep the distance to the nearest vertex (a k-d tree
// query), which is never less than the exact one and exceeds it by less than the mesh's longest
// edge.
//
// Sealed faces: triangles the caller marks as sealed (lying on a domain wall, inside a static box)
// are no way out. They still decide inside and outside, but distances are measured to the other
// triangles only, so that a particle found inside an object standing on the floor is sent out
// through its sides or top, not down through its base into the floor (where the walls' rule would
// put it back inside the object).
#pragma once
#include <cstddef>
#include <functional>
#include <vector>

#include "sampling/lattice.hpp"
#include "sampling/mesh.hpp"

namespace mw {

struct SignedDistanceGrid {
    LatticeGrid grid;              // the nodes; spacing may be coarser than asked (max_nodes)
    std::vector<double> distance;  // per node, in LatticeGrid::index order; negative inside
    std::size_t exit_triangles = 0;  // triangles distances are measured to (not sealed); 0: no grid
    double seconds = 0;              // wall time of the build
};

// Whether the triangle with these corners (the mesh oriented outward) is sealed.
using SealedFace = std::function<bool(const Vec3d& a, const Vec3d& b, const Vec3d& c)>;

// The grid covers the bounding box of the mesh's triangles grown by `band` plus two nodes on every
// side, at `spacing`, or, when that would take more than `max_nodes` nodes (0: no limit; else at
// least 8), at the smallest spacing that fits them. Exact distances reach that margin. The mesh is
// validated (InputError naming its source) and oriented outward first, as the samplers do;
// vertices no triangle uses are ignored. When every triangle is sealed, no grid is built
// (exit_triangles 0, no nodes).
SignedDistanceGrid signed_distance_grid(TriangleMesh mesh, double spacing, double band, std::size_t max_nodes,
                                        const SealedFace& sealed = nullptr);

// Distance from p to the triangle (a, b, c): to its plane where p projects inside it, otherwise
// to the nearest of its edges (a degenerate triangle is its edges).
double point_triangle_distance(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c);

}  // namespace mw
