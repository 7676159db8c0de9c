// Meshes to particles: one call turns a solid's triangle mesh into the three linked particle sets
// of the coupling method (docs/method.md, "Particles"): IBPs on the inner lattice, SBPs on the surface
// and GPs at the mesh vertices. Host only, double precision; convert to Real when uploading.
#pragma once
#include <cstdint>

#include "sampling/geometry_links.hpp"
#include "sampling/inside_outside.hpp"
#include "sampling/lattice_sampler.hpp"
#include "sampling/mesh.hpp"
#include "sampling/mesh_refinement.hpp"
#include "sampling/surface_sampler.hpp"

namespace mw {

struct SampleOptions {
    InsideOutsideOptions inside;
    SurfaceOptions surface;
    // Coverage check (statistics only): random probes per r0² of surface, clamped to [min, max].
    bool measure_coverage = true;
    double coverage_probes_per_r0sq = 16;
    std::size_t coverage_min_probes = 20000;
    std::size_t coverage_max_probes = 2000000;
    // Edges longer than this (× r0) are split for the GPs, and the SBPs' triangles and weights
    // moved onto the refined mesh (mesh_refinement.hpp: a coarse mesh would hand a face's whole
    // fluid force to the IBPs at its corners). 0 keeps the mesh's own vertices as the GPs.
    double geometry_max_edge = 1.0;
};

struct SampleTimings {  // seconds, wall clock
    double prepare = 0;   // validation, orientation, edge analysis
    double embree = 0;    // Embree BVH build (part of inner)
    double refine = 0;    // winding-number refinement near holes (part of inner)
    double inner = 0;     // inside/outside ray casts + IBP lattice + one-ring connectivity
    double surface = 0;   // SBPs
    double geometry = 0;  // mesh refinement and GP links
    double coverage = 0;  // the coverage check (statistics, not needed for a run)
    double total = 0;     // everything but the coverage check
};

struct SampleStats {
    std::size_t ibp_count = 0, sbp_count = 0, gp_count = 0;
    std::size_t triangles = 0, boundary_edges = 0;
    std::size_t geometry_triangles = 0;  // of the mesh the GPs are the vertices of (refined)
    bool closed = false;
    bool flipped = false;       // the mesh had negative signed volume and was re-oriented
    double mesh_volume = 0;     // signed volume after orientation
    double mesh_area = 0;
    double ibp_volume = 0;      // ibp_count × r0³
    double largest_gap = -1;    // from the coverage check (-1 when not measured)
    double mean_gap = -1;
    std::size_t coverage_probes = 0;
    std::size_t ambiguous_points = 0;  // lattice points where ray directions disagreed
    std::size_t refined_points = 0;    // of those, decided by the winding number (open meshes)
    int ray_directions = 0;
    std::size_t rays = 0;
    std::size_t sbp_candidates = 0, sbp_filled = 0;
    std::size_t gps_without_ibp = 0;
    std::size_t ibp_links_per_gp_min = 0, ibp_links_total = 0;
};

struct SolidSample {
    double spacing = 0;         // r0
    double support_radius = 0;  // h
    InnerParticles ibp;
    SurfaceParticles sbp;  // triangles and weights refer to `geometry`
    GeometryLinks gp;      // the vertices of `geometry`
    TriangleMesh geometry;  // the mesh oriented outward, refined (SampleOptions::geometry_max_edge)
    SampleStats stats;
    SampleTimings timings;
};

// Validates (throws InputError naming mesh.source), orients outward (flips a mesh with negative
// signed volume), then samples. spacing = r0 > 0, support_radius = h > 0.
SolidSample sample_solid(const TriangleMesh& mesh, double spacing, double support_radius, const SampleOptions& options = {});

}  // namespace mw
