// Refining a moving object's mesh so that no edge is longer than a given length, for its GPs.
//
// Why: an elastic object's SBPs follow the GPs of their triangle (barycentric weights), and the
// fluid's force on an SBP reaches the IBPs through the same weights, transposed (coupling.hpp).
// On a coarse mesh (a procedural box has 8 vertices and 12 triangles) the whole pressure on a
// face therefore lands on the few IBPs linked to its corner GPs, and the face can only move as
// its corners do. Unrefined, in scenes/melting_ice.json's pool with a 0.3 m elastic box (not
// melting), a corner of the box's bottom shoots up at 6 m/s in its eleventh step (t = 0.044 s),
// lifting the whole face with it, and PCISPH diverges at step 73. With no edge longer than r0
// each SBP's force stays within about h of it (docs/sampling.md).
//
// How: edges longer than the limit are split at their midpoints, each triangle into 2, 3 or 4
// according to how many of its edges split (the midpoint shared by both triangles of an edge, so
// a closed mesh stays closed and no vertex moves), until none is longer. Every refined triangle
// lies inside one triangle of the input, so a point given on the input (a triangle and
// barycentric weights, as the surface sampler gives its SBPs) is found again on the refined mesh
// by descending the splits: its position, and hence every SBP, is unchanged. (Remeshers such as
// CGAL's isotropic remeshing move vertices and keep no such map, so they do not serve here.)
#pragma once
#include <vector>

#include "sampling/mesh.hpp"

namespace mw {

struct RefinedMesh {
    TriangleMesh mesh;  // the input's vertices first, in their order, then the midpoints
    // The split history, one entry per pass: for each triangle of that pass's input, its
    // children (indices into the next pass's triangles) and the children's corners in the
    // parent's barycentric coordinates.
    struct Split {
        std::vector<int> first_child;  // [triangle + 1]: children first_child[t] .. first_child[t + 1]
        std::vector<std::array<Vec3d, 3>> child_corners;  // per child of the next pass
    };
    std::vector<Split> passes;

    // A point of input triangle `triangle` at barycentric weights `bary`: its triangle on the
    // refined mesh and its weights there (the same position to rounding).
    void locate(int& triangle, Vec3d& bary) const;
};

// Splits edges longer than `max_edge` (> 0) until none is. Throws InputError (naming
// mesh.source) when that would take more than `max_triangles` triangles.
RefinedMesh refine_long_edges(const TriangleMesh& mesh, double max_edge, std::size_t max_triangles = 20000000);

}  // namespace mw
