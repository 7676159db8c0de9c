// A frame as render/preview.hpp draws it, from the program's own data: the particles (as
// Simulation::download gives them, or as read back from a VTU frame), the solids' meshes and the
// fluid's surface, with the camera, size and colour field of the scene's output.preview.
#pragma once
#include <array>
#include <optional>
#include <vector>

#include "apps/scene.hpp"
#include "render/image.hpp"
#include "render/preview.hpp"
#include "sampling/mesh.hpp"
#include "simulation/simulation.hpp"

namespace mw {

// A mesh for the preview: a solid's (grey, opaque) or the fluid's surface (water blue, translucent).
PreviewMesh solid_preview_mesh(const std::vector<std::array<double, 3>>& vertices,
                               const std::vector<std::array<int, 3>>& triangles);
// In 2D the surface is a contour (edges (a, b, a), surface/contour.hpp): drawn as a band
// `line_width` wide in front of the plane's particles, the camera looking at it head-on.
PreviewMesh surface_preview_mesh(const TriangleMesh& surface, double line_width);
// The contour's band, in r0: about two pixels at the preview's default size on a 2D scene a
// hundred r0 wide.
constexpr double kContourWidthInR0 = 0.3;
// A rod drawn as a tube of `radius` (r0/2) round its line: a hexagonal prism per segment, each
// ring square to the line there (the mean of its segments' directions).
PreviewMesh rod_tube(const std::vector<std::array<double, 3>>& line, double radius);
// Whether an object is drawn as its mesh, its particles hidden: a rod (as its tube) always; a
// melting object never (its particles show what is left); in 2D nothing else (an outline has no
// faces to draw: its particles show it).
bool drawn_as_mesh(SolidKind kind, bool melts, int dimensions);
// The solids' meshes at this frame (SolidSetup GPs in `particles`; static objects: their rest mesh).
std::vector<PreviewMesh> object_preview_meshes(const std::vector<SolidSetup>& solids, const HostParticles& particles,
                                               int dimensions);

// The picture of frame `index` at time `time`. `speed_scale` (m/s): the top of the speed colour
// bar, the same in every frame of a run (0: the frame's own range).
Image preview_picture(const Scene& scene, const HostParticles& particles, std::vector<PreviewMesh> meshes, double time,
                      int index, double speed_scale);

}  // namespace mw
