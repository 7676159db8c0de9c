// Scenes: JSON in, a validated Scene out. Every key is checked against the schema (docs/scenes.md):
// an unknown key, a wrong type or an out-of-range value throws InputError naming the full key path
// (for example `solver.eta` or `fluid_blocks[1].min`). `--set path.to.key=value` overrides are
// applied to the raw JSON before validation, so they go through the same checks.
#pragma once
#include <array>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "simulation/simulation.hpp"

namespace mw {

using SceneJson = nlohmann::ordered_json;  // keeps the keys in the order they were written

struct FluidBlock {
    Vec3 min{}, max{};
    Vec3 velocity{0, 0, 0};
    // An elastic or rigid object's SBPs, spaced this many r0 apart at most (1: the method's r0).
    double surface_spacing = 1;
    Real temperature = 20;  // C, with heat conduction (fluid.temperature by default)
};

struct StaticBox {
    Vec3 min{}, max{};
    int layers = 1;
};

// A solid object from a mesh (docs/scenes.md, "objects"; docs/lsm.md): its parameters (the solids
// module's), the mesh and where it goes, and the apps' part (start, pins).
struct SceneObject : SolidParams {
    std::string name;
    std::string mesh_file;        // an OBJ file (relative paths: from the scene file's folder) ...
    std::string mesh_file_given;  // ... as the scene wrote it (mesh_file is made absolute)
    std::string mesh_procedural;  // ... or a procedural spec such as "box:x=0.5,y=0.1,z=0.1"
    Vec3 scale{1, 1, 1}, rotation_deg{0, 0, 0}, translation{0, 0, 0};
    Vec3 velocity{0, 0, 0};
    // An elastic or rigid object's SBPs, spaced this many r0 apart at most (1: the method's r0).
    double surface_spacing = 1;
    Real temperature = 20;  // C, with heat conduction (fluid.temperature by default)
    enum class Pin { kNone, kBoxes, kHalfSpace } pin = Pin::kNone;
    Vec3 pin_min{}, pin_max{};       // the box being read
    std::vector<std::pair<Vec3, Vec3>> pin_boxes;  // boxes: IBPs inside any of them are pinned
    Vec3 pin_point{}, pin_normal{};  // half-space: IBPs with (x - point).normal < 0 are pinned
};

// A fluid emitter (docs/scenes.md, "emitters"; algorithms/emitter.hpp).
struct SceneEmitter : EmitterParams {
    std::string name;
};

// output.formats as flags: what each frame writes (apps/frame_writer.hpp).
struct FrameFormats {
    bool vtu = false;      // particles as VTK XML (ParaView)
    bool ply = false;      // particles, and the surface with "surface", as binary PLY (Blender, Houdini)
    bool surface = false;  // the fluid's surface mesh as OBJ
    bool vdb = false;      // the fluid's level set and colour field as OpenVDB grids
    bool preview = false;  // a PNG picture of the frame
    bool particles() const { return vtu || ply; }
    bool color_field() const { return surface || vdb; }  // both start from the colour field
};

// output.preview: the pictures of output.formats "preview" and `meltwater render` (render/preview.hpp).
enum class PreviewField { kSpeed, kPressure, kDensity, kTemperature };
struct PreviewSettings {
    int width = 960, height = 540;  // pixels
    PreviewField field = PreviewField::kSpeed;  // what colours the fluid
    Vec3 eye{0, 0, 0}, target{0, 0, 0};  // the camera (defaults frame the domain)
    double fov = 35;                     // vertical field of view, degrees (default_camera frames with it)
};

struct Scene {
    std::string name;
    std::string description;
    std::string source;       // the file it came from, or "built-in default scene"
    SimulationParams params;  // every module's parameters
    Real boundary_spacing_factor = 0.5;  // boundary.spacing_factor: boundary spacing = factor x r0
    int boundary_layers = 1;             // boundary.layers
    // boundary.max_lost_fraction: the run stops (exit 4) once more than this share of the fluid has
    // left the domain. With walls a loss means a leak or a blow-up (default 1%); an open domain lets
    // fluid out by design (default 1: never stop).
    double max_lost_fraction = 0.01;
    // solver.max_density_error: the run stops (exit 4) at the first step that ends with a peak
    // density error above this. With the walls' correction a blow-up shows as fluid packed far
    // above its rest density rather than as lost fluid.
    double max_density_error = 1.0;
    // solver.max_speed, m/s: the run stops (exit 4) at the first step that ends with a fluid
    // particle or a solid's particle faster than this. None (null, the default): 20 times the
    // scene's speed scale (speed_limit.hpp).
    std::optional<double> max_speed;
    Real fluid_temperature = 20;  // fluid.temperature, C: the fluid blocks' and objects' default
    std::vector<FluidBlock> fluid_blocks;
    std::vector<StaticBox> static_boxes;
    std::vector<SceneObject> objects;
    std::vector<SceneEmitter> emitters;
    std::vector<PressureSensorSetup> pressure_sensors;  // docs/scenes.md, "Pressure sensors"
    std::string base_dir;  // folder of the scene file ("" for text scenes): mesh paths are relative to it
    double end_time = 1.0;  // run.end_time, s
    double fps = 30;        // output.fps: frames per simulated second
    std::vector<std::string> formats{"vtu"};  // output.formats (FrameFormats)
    double surface_voxel = 0.5;  // output.surface.voxel: the surface field's node spacing, in r0
    PreviewSettings preview;     // output.preview
    SceneJson resolved;  // every key with its value, defaults filled in, overrides applied

    bool walls() const { return params.boundary.walls; }
    Real boundary_spacing() const { return boundary_spacing_factor * params.fluid.spacing; }
    // Whether the scene has fluid from the start or from an emitter (melting objects aside).
    bool has_fluid() const { return !fluid_blocks.empty() || !emitters.empty(); }
    // How far outside the domain faces the walls' first layer goes (sampling/wall_gap.hpp), m.
    Real wall_gap() const;
    FrameFormats frame_formats() const;
    bool writes_vtu() const { return frame_formats().vtu; }
    bool writes_surface() const { return frame_formats().surface; }
    bool writes_frames() const { return !formats.empty(); }
    // A warning for a kernel the scene's support radius makes unstable ("" when there is none):
    // the cubic spline wider than 2.25 r0 (docs/solver.md, "Kernels").
    std::string kernel_warning() const;
    // Heat conduction (docs/heat.md): the largest thermal diffusivity among the fluid and the
    // moving objects.
    double largest_heat_diffusivity() const;
};

// Every scene key, in the order the reader reads them, for the reference table of docs/scenes.md
// (`meltwater schema`).
std::vector<ParamDoc> scene_schema();

// A warning when the largest step needs more heat sub-steps than heat.max_substeps allows ("" when
// it does not; Simulation::heat_substeps_needed gives `needed`).
std::string heat_substeps_warning(int needed, int max_substeps);

// The built-in default scene (scenes/dam_break.json, embedded at configure time).
const char* default_scene_text();

// Loads a scene from `path` ("" = the built-in default), applies `overrides` (each "key.path=value")
// in order, and validates. Throws InputError naming the file, key or override on any problem.
Scene load_scene(const std::string& path, const std::vector<std::string>& overrides = {});

// Same, from JSON text; `source` names it in messages.
Scene parse_scene_text(const std::string& text, const std::string& source,
                       const std::vector<std::string>& overrides = {});

// Validates an already-parsed JSON scene (no overrides).
Scene resolve_scene(const SceneJson& raw, const std::string& source);

// "[x, y, z] to [x, y, z]" and "[x, y, z]", for messages (6 significant digits).
std::string describe_box(Vec3 lo, Vec3 hi);
std::string describe_point(Vec3 p);

}  // namespace mw
