// Procedural meshes made by the project. Every maker returns a closed, outward-oriented mesh
// centred on the origin (bounding-box centre), y up, except make_sheet, which is open (one layer,
// for cloth), and make_line, which has no triangles (a rod's centreline). Sizes are in metres. Invalid parameters throw InputError.
#pragma once
#include <map>
#include <string>

#include "sampling/mesh.hpp"

namespace mw {

TriangleMesh make_box(const Vec3d& size);
// Box with a closed cavity: the outer box of `size` and an inner, inward-facing box inset by
// `wall` on every side. With open_top the cavity opens through the top face (a container).
TriangleMesh make_hollow_box(const Vec3d& size, double wall, bool open_top = false);
// Icosphere: 20·4^subdivisions triangles, vertices on the sphere.
TriangleMesh make_sphere(double radius, int subdivisions = 4);
// Torus around the y axis: major radius (centre of the tube), minor radius (tube).
TriangleMesh make_torus(double major_radius, double minor_radius, int major_segments = 48, int minor_segments = 24);
// Cylinder along y with flat caps.
TriangleMesh make_cylinder(double radius, double height, int segments = 48);
// Staircase solid: `steps` steps rising in +y along +z; each step has the given width (x), tread
// depth (z) and riser height (y).
TriangleMesh make_stairs(int steps, double width, double depth, double height);
// Flat open sheet in the xz plane (normal +y), nx × nz quads.
TriangleMesh make_sheet(double size_x, double size_z, int nx, int nz);
// A straight line along x through the origin: its two end points, no triangles (a rod's centreline).
TriangleMesh make_line(double length);

// By name with named parameters, for scenes and the command line:
//   box: x y z | hollow_box: x y z wall open_top | sphere: radius subdivisions |
//   torus: major minor major_segments minor_segments | cylinder: radius height segments |
//   stairs: steps width depth height | sheet: x z nx nz | line: length
// A missing parameter takes its default (see procedural_meshes.cpp); an unknown name or
// parameter throws InputError.
TriangleMesh make_procedural(const std::string& kind, const std::map<std::string, double>& params);
// Parses "kind" or "kind:key=value,key=value" (e.g. "sphere:radius=0.5,subdivisions=5").
TriangleMesh make_procedural_from_spec(const std::string& spec);
// A spec's parts: "kind" or "kind:key=value,key=value" (throws InputError on a malformed pair).
struct ProceduralSpec {
    std::string kind;
    std::map<std::string, double> params;
};
ProceduralSpec parse_procedural_spec(const std::string& spec);
// `defaults` overridden by `given`; throws InputError naming `kind` on an unknown or non-finite one.
std::map<std::string, double> procedural_parameters(const std::string& kind, const std::map<std::string, double>& defaults,
                                                    const std::map<std::string, double>& given);
// "kind:key=value,..." of the parameters given (a made shape's source, for messages).
std::string procedural_source(const std::string& kind, const std::map<std::string, double>& given);
// True when `spec` names a procedural mesh ("kind" or "kind:..." with a known kind).
bool is_procedural_spec(const std::string& spec);

}  // namespace mw
