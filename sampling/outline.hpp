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

// True when every "triangle" of `mesh` is an edge (two equal corners): an outline, not a surface.
bool is_outline(const TriangleMesh& mesh);
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
// Whether point p (x, y) lies inside the outline by the even-odd rule.
bool inside_outline(const TriangleMesh& outline, const std::vector<std::array<int, 2>>& edges, double x, double y);

}  // namespace mw
