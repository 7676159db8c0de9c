#include "apps/run_estimate.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace mw {

namespace {
// Bytes a point takes in a frame: position, velocity (3 floats each), density, pressure (float),
// type (byte), object, id (int32), temperature (float, with heat); VTU adds its vertex cells
// (connectivity and offset as Int64, a type byte).
double point_bytes(const Scene& scene, bool vtu) {
    const double fields = 12 + 12 + 4 + 4 + 1 + 4 + 4 + (scene.params.heat.enabled ? 4 : 0);
    return vtu ? fields + 17 : fields;
}

// The starting fluid's surface area, m²: the fluid blocks' faces.
double fluid_block_area(const Scene& scene) {
    double area = 0;
    for (const FluidBlock& b : scene.fluid_blocks) {
        const double x = double(b.max.x - b.min.x), y = double(b.max.y - b.min.y), z = double(b.max.z - b.min.z);
        area += 2 * (x * y + y * z + z * x);
    }
    return area;
}
}  // namespace

DiskEstimate estimate_disk(const Scene& scene, const ParticleCounts& counts, const SimulationSetup& setup) {
    DiskEstimate e;
    const FrameFormats formats = scene.frame_formats();
    e.frames = scene.writes_frames() ? 1 + static_cast<long>(std::floor(scene.end_time * scene.fps + 1e-9)) : 0;
    const double frames = double(e.frames);
    const double fixed = double(counts.by_type[kStaticBoundary]);
    const double moving = double(counts.total()) - fixed;  // pending included: all released by the end
    const auto add = [&e](const std::string& name, double bytes) {
        if (bytes <= 0) return;
        e.parts.emplace_back(name, bytes);
        e.total += bytes;
    };
    if (formats.vtu) add("particles (vtu)", (moving * frames + fixed) * point_bytes(scene, true));
    if (formats.ply) add("particles (ply)", (moving * frames + fixed) * point_bytes(scene, false));
    // Objects' meshes: OBJ text, about 32 bytes a vertex line and 24 a face line.
    double object_bytes = 0;
    for (const SolidSetup& o : setup.solids)
        if (!o.melts() && !o.triangles.empty())
            object_bytes += 32.0 * double(std::max(o.gp.size(), o.rest_vertices.size())) + 24.0 * double(o.triangles.size());
    if (formats.particles() || formats.surface || formats.vdb || formats.preview) add("objects' meshes (obj)", object_bytes * frames);
    // The surface mesh has about one vertex per voxel face crossed and two triangles per vertex.
    const double voxel = scene.surface_voxel * double(scene.params.fluid.spacing);
    const double surface_vertices = fluid_block_area(scene) / (voxel * voxel);
    if (surface_vertices > 0 && (formats.surface || formats.vdb)) e.surface_estimated = true;
    if (formats.surface) add("surface (obj)", frames * surface_vertices * (32.0 + 2 * 24.0));
    if (formats.surface && formats.ply) add("surface (ply)", frames * surface_vertices * (12.0 + 2 * 13.0));
    // The level set's narrow band (about 6 voxels across the surface) and the fog volume's nodes
    // (the fluid's bounding box), a float each and OpenVDB's tree around them.
    if (formats.vdb) {
        double fluid_nodes = 0;
        for (const FluidBlock& b : scene.fluid_blocks)
            fluid_nodes += double(b.max.x - b.min.x) * double(b.max.y - b.min.y) * double(b.max.z - b.min.z) /
                           (voxel * voxel * voxel);
        add("fluid grids (vdb)", frames * 4.5 * (6 * surface_vertices + fluid_nodes));
    }
    // A preview compresses to about 0.63 bytes a pixel (the default dam break's 46 pictures at
    // 960 x 540: 15 MiB).
    if (formats.preview) add("previews (png)", frames * 0.63 * double(scene.preview.width) * double(scene.preview.height));
    return e;
}

TimeEstimate time_steps(Simulation& sim, const Scene& scene, double end_time, int steps) {
    TimeEstimate t;
    if (steps <= 0) return t;
    sim.step();  // the first step builds what later steps reuse: not timed
    const auto start = std::chrono::steady_clock::now();
    const double time_before = sim.time();
    for (int s = 0; s < steps; ++s) sim.step();
    const double simulated = sim.time() - time_before;
    t.steps_timed = steps;
    t.ms_per_step = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count() / steps;
    const SolverParams& solver = scene.params.solver;
    const double dt = solver.dt_mode == TimeStepMode::kCfl ? double(solver.dt) : simulated / steps;
    t.lower_bound = solver.dt_mode == TimeStepMode::kCfl;
    t.steps_to_end = dt > 0 ? std::ceil(end_time / dt - 1e-9) : 0;
    t.seconds = t.steps_to_end * t.ms_per_step / 1000.0;
    return t;
}

}  // namespace mw
