// A software preview of one frame of a simulation, for `output.formats: ["preview"]` and
// `meltwater render`: a picture a person can read at a glance on any machine, with no GPU, no
// display and no outside renderer.
//
// What it draws, back to front in one z-buffer (nearest surface wins at each pixel):
// - the domain's floor as a two-tone checkerboard and its twelve edges as thin lines, so that the
//   viewer can tell up from down and near from far;
// - every visible particle as a shaded sphere splat: a disc on the screen whose depth per pixel
//   follows the sphere's bulge, lit by Lambert plus ambient from a light fixed to the camera (so
//   every view is lit from the upper left). Fluid is coloured by the frame's field through
//   colour_map, solids are grey, the static walls' particles are left out unless asked for (they
//   would hide the fluid behind a wall of dots);
// - triangle meshes (the solids' meshes, the fluid's surface), smooth-shaded with the same light,
//   opaque, or translucent over what lies behind them (only the nearest translucent layer counts);
// - a legend (the field's name, a colour bar and its range) and an optional caption line.
//
// The projection is a pinhole perspective; points behind the camera, or closer to it than their
// own radius, are left out. Work is split over OpenMP threads by bands of rows, each band drawing
// its primitives in one fixed order (splats nearest first, then triangles as given), so the
// picture is the same bit for bit at any thread count.
#pragma once
#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "render/image.hpp"

namespace mw {

using PreviewVec = std::array<double, 3>;

struct PreviewCamera {
    PreviewVec eye{0, 0, 1};
    PreviewVec target{0, 0, 0};
    PreviewVec up{0, 1, 0};
    double fov_y_degrees = 35;  // vertical field of view
};

// A three-quarter view from above and in front (+z, a little to +x) of the box whose corners are
// lo and hi (y up), far enough that all eight corners fall inside a picture of the given width /
// height, and panned so the box sits in the middle of it. `head_on`: from straight in front (+z),
// the view of a 2D scene's plane, the box in the part of the picture left of the legend.
PreviewCamera default_camera(const PreviewVec& domain_lo, const PreviewVec& domain_hi, double aspect = 16.0 / 9.0,
                             bool head_on = false);

enum class PreviewKind : std::uint8_t {
    fluid,     // coloured by the field
    solid,     // grey (an object's particles)
    boundary,  // a static wall's particles: drawn only with PreviewStyle::show_boundary
    hidden,    // never drawn
};

struct PreviewMesh {
    std::vector<float> vertices;            // x, y, z per vertex
    std::vector<std::uint32_t> triangles;   // three vertex indices per triangle
    Rgb colour{150, 150, 150};
    float opacity = 1;                      // below 1: blended over what lies behind
    bool smooth = true;                     // normals averaged at the vertices, else one per face
};

struct PreviewFrame {
    // One entry per particle in each of positions (x, y, z), values and kinds. values may be empty:
    // the fluid is then drawn in water blue and the legend left out.
    std::vector<float> positions;
    std::vector<float> values;
    std::vector<PreviewKind> kinds;
    double particle_radius = 0.01;  // world units: half the particle spacing
    std::string field_name;         // the legend's title, e.g. "speed, m/s"
    // The values mapped to the colour bar's ends; unset, preview_field_range picks them.
    std::optional<std::array<double, 2>> field_range;
    std::vector<PreviewMesh> meshes;
    std::optional<std::array<PreviewVec, 2>> domain;  // lo, hi: the floor and the edges
    std::string caption;                              // e.g. "t = 0.250 s  frame 12"; empty: none
};

struct PreviewStyle {
    int width = 960, height = 540;
    Rgb background_top{206, 214, 224}, background_bottom{244, 245, 247};  // a vertical gradient
    Rgb solid_colour{160, 160, 160};
    Rgb boundary_colour{196, 190, 180};
    Rgb water_colour{60, 120, 200};  // the fluid when the frame has no values
    std::array<Rgb, 2> floor_colours{{{222, 218, 210}, {200, 196, 188}}};  // the checkerboard
    Rgb edge_colour{80, 84, 96};
    bool show_boundary = false;
    bool show_legend = true;
    double ambient = 0.35;       // the light's share everywhere; the rest follows the surface's slope
    double splat_scale = 1.0;    // each splat's radius over the particle radius
    int supersample = 2;         // pixels per side rendered for each pixel of the picture (1 to 4)
};

// The range of the frame's fluid values the colour bar spans when the frame sets none: the 1st to
// the 99th percentile (one fast particle should not turn the rest into one colour), or the minimum
// and maximum when the percentiles coincide; widened when every value is the same.
std::array<double, 2> preview_field_range(const PreviewFrame& frame);

// The picture of the frame. Throws std::invalid_argument when the frame's arrays disagree in
// length, a mesh names a vertex it lacks, or the style's size or supersampling is out of range.
Image render_preview(const PreviewFrame& frame, const PreviewCamera& camera, const PreviewStyle& style = {});

}  // namespace mw
