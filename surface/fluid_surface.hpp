// Surface reconstruction: the fluid's colour field (algorithms/surface_field.hpp) on a box of
// nodes, turned into a closed triangle mesh at its iso-value by OpenVDB's mesher (host only,
// at frame times). The field is the product's own (the SPH kernel, computed by the backend);
// the meshing is a well-kept library's. docs/surface.md.
#pragma once
#include <array>
#include <cstddef>
#include <vector>

#include "simulation/simulation.hpp"
#include "sampling/mesh.hpp"

namespace mw {

// The most nodes a frame's field may take (a Real each on the device and on the host, and a
// float more on the host while meshing): 2^28.
constexpr std::size_t kMaxSurfaceNodes = std::size_t(1) << 28;

// The nodes per axis of the box around fluid whose particles span [lo, hi]: grown by one support
// radius and a node and a quarter (surface_nodes_around_fluid says why), at `spacing`; in 2D one
// plane of nodes (z = 0). In double: the scene's check (most_surface_nodes) asks it of boxes too
// large for an int.
std::array<double, 3> surface_node_dims(Vec3 lo, Vec3 hi, Real support_radius, Real spacing, int dimensions);

// The most nodes a frame of a simulation of `params` can need at `spacing`: the box around fluid
// anywhere within one support radius of the domain (what surface_nodes_around_fluid keeps).
double most_surface_nodes(const SimulationParams& params, Real spacing);

// The node box around the fluid particles among `particles` (type kFluid) that lie within one
// support radius of the domain [domain_min, domain_max] (fluid lost beyond is left out); no node
// at all (dims 0) without such fluid; in 2D (`dimensions`) the plane z = 0. Throws
// std::logic_error past kMaxSurfaceNodes, which resolve_scene's check of output.surface.voxel
// (most_surface_nodes) rules out.
SurfaceNodes surface_nodes_around_fluid(const HostParticles& particles, Vec3 domain_min, Vec3 domain_max,
                                        Real support_radius, Real spacing, int dimensions);

// The level set c = iso of the colour field `color` at `nodes` (c above iso is fluid), wound
// counter-clockwise seen from outside the fluid. `threads`: at most that many threads for the
// mesher (0: all).
TriangleMesh mesh_color_field(const SurfaceNodes& nodes, const std::vector<Real>& color, double iso, int threads);

// One frame's surface of a simulation, as `meltwater run` writes it and bench_fluid times it:
// the node box from the particles, the colour field on the simulation's backend, the mesh (in
// 2D the contour, surface/contour.hpp).
class FluidSurfacer {
   public:
    // Nodes `voxel_in_r0` r0 apart (output.surface.voxel); `threads` as for mesh_color_field.
    FluidSurfacer(const SimulationParams& params, double voxel_in_r0, int threads);
    // The colour field at a frame: its nodes (none without fluid), values and iso-value, and the
    // milliseconds it took (grid build, field, host copy).
    struct Field {
        SurfaceNodes nodes;
        std::vector<Real> color;
        double iso = 0;
        double ms = 0;
    };
    struct Surface {
        TriangleMesh mesh;
        double ms = 0;        // all of it
        double field_ms = 0;  // of which the colour field
    };
    // `particles`: `sim`'s, as download() gave them at its current time. The field is kept until
    // the next call (the next frame's reuses its storage); build() computes it too.
    const Field& field(Simulation& sim, const HostParticles& particles);
    Surface build(Simulation& sim, const HostParticles& particles);
    const Field& last_field() const { return field_; }

   private:
    Vec3 domain_min_, domain_max_;
    Real support_radius_, spacing_;
    int dimensions_;
    int threads_;
    Field field_;
};

}  // namespace mw
