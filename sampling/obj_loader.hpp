// Wavefront OBJ input through tinyobjloader (polygons are triangulated; all shapes are merged
// into one mesh; normals, texture coordinates and materials are ignored). An OBJ of one polyline
// ("l") and no faces is a rod's centreline: its points in the line's order, no triangles. In a
// file with faces, lines are not read.
#pragma once
#include <string>

#include "sampling/mesh.hpp"

namespace mw {
// Loads and validates (validate_mesh with require_volume). Throws InputError naming the file:
// missing or unreadable file, parse error, no triangles, a vertex line with fewer than 3
// coordinates or one that is not a finite number, a face with fewer than 3 corners or an index
// that is 0, not a number or past the vertices (these name the vertex or face and the line), a
// coordinate out of range, no volume; for a polyline, a line of fewer than 2 points, an index as
// for a face, a vertex visited twice, or more than one line.
TriangleMesh load_obj(const std::string& path, bool require_volume = true);
// An OBJ of line elements and no faces as an outline (sampling/outline.hpp): each pair of
// consecutive points of a line one edge (a, b, a). What the frames of a 2D object and of the 2D
// fluid's contour hold; a file with no vertex gives an empty mesh. Throws InputError naming the
// file when it cannot be read or parsed, holds faces, or a line names a vertex it lacks.
TriangleMesh load_obj_edges(const std::string& path);
// The same from OBJ text (source names it in messages); used by tests.
TriangleMesh parse_obj(const std::string& text, const std::string& source, bool require_volume = true);
}  // namespace mw
