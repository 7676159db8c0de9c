// A 2D object's shape: closed loops in the plane z = 0 (an outer boundary and any holes), held as
// a TriangleMesh whose "triangles" are the loops' edges (a, b, a). That is the form its SBPs link
// to (algorithms/lsm_regions.hpp, SbpLink::is_outline_edge), and it passes through the scene's
// transform, bounding box and frame writers as a mesh does. Which side of an edge is solid is
// decided where it is sampled (outline_sample.hpp), by the even-odd rule, so loops may run
// either way round and a mirroring transform needs no care.
#pragma once
#include <map>
#include <string>
#include <vector>

#include "sampling/mesh.hpp"

namespace mw {

// Whether a mesh "triangle" is an outline's edge (a, b, a). The device reads the same form from
// an SBP's link (SbpLink::is_outline_edge in algorithms/lsm_regions.hpp, which cannot include this).
inline bool is_outline_edge(const std::array<int, 3>& t) { return t[2] == t[0] && t[1] != t[0]; }
// True when there are triangles and every one is an edge (a, b, a): an outline, not a surface.
bool is_outline(const std::vector<std::array<int, 3>>& triangles);
inline bool is_outline(const TriangleMesh& mesh) { return is_outline(mesh.triangles); }
// The edges (a, b) of an outline, one per "triangle", in its order.
std::vector<std::array<int, 2>> outline_edges(const TriangleMesh& outline);

// Closed loops (each at least 3 points, the last not repeating the first) to an outline.
// Throws InputError naming `source` on a non-finite point, a loop of fewer than 3 distinct points,
// a zero-length edge, or two edges that cross or touch.
TriangleMesh make_outline(const std::vector<std::vector<Vec3d>>& loops, const std::string& source);

// Procedural outlines, centred on the origin, sizes in metres:
//   rectangle: x y | hollow_rectangle: x y wall open_top | circle: radius segments |
//   ring: radius wall segments
// hollow_rectangle's open_top opens its cavity through the top side (a U, one loop).
TriangleMesh make_outline_procedural(const std::string& kind, const std::map<std::string, double>& params);
// "kind" or "kind:key=value,..." (as make_procedural_from_spec), for scenes.
TriangleMesh make_outline_from_spec(const std::string& spec);
bool is_outline_spec(const std::string& spec);

// An outline file (docs/scenes.md, "Two dimensions"): text, one point "x y" per line, a blank
// line between loops, '#' starting a comment. Throws InputError naming the file and line.
TriangleMesh load_outline(const std::string& path);

// The edges oriented with the solid on their left (tested just beside each edge's middle): the
// outer loops run counter-clockwise, the holes clockwise, whatever order they were given in.
std::vector<std::array<int, 2>> oriented_outline_edges(const TriangleMesh& outline);
// The edges' total length, m.
double outline_perimeter(const TriangleMesh& outline);
// The area enclosed (even-odd: holes subtract), m².
double outline_area(const TriangleMesh& outline);
// Whether the point (x, y) lies inside the loops `edges` over `points` by the even-odd rule.
bool inside_loops(const std::vector<Vec3d>& points, const std::vector<std::array<int, 2>>& edges, double x, double y);
inline bool inside_outline(const TriangleMesh& outline, const std::vector<std::array<int, 2>>& edges, double x, double y) {
    return inside_loops(outline.vertices, edges, x, y);
}
// Twice the signed area a closed loop of `edges` over `points` encloses (the shoelace sum):
// positive when it runs counter-clockwise.
double twice_signed_area(const std::vector<Vec3d>& points, const std::vector<std::array<int, 2>>& edges);

}  // namespace mw
