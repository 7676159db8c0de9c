#include "sampling/solid_sample.hpp"

#include <chrono>
#include <cmath>
#include <sstream>

#include "common/errors.hpp"

namespace mw {

namespace {
using Clock = std::chrono::steady_clock;
// The inside/outside test locates surface crossings in single precision, relative to the mesh's
// bounding box: to about 1e-6 of its diagonal (a few float ulps of distances up to three
// diagonals; crossings that close are also merged into one). At 1e5 spacings across the mesh
// that is 0.1 r0, still well within a lattice cell; finer, a wall one spacing thick could vanish.
constexpr double kMaxSpacingsAcrossMesh = 1e5;
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }
}  // namespace

SolidSample sample_solid(const TriangleMesh& input, double spacing, double support_radius, const SampleOptions& options) {
    const std::string src = input.source.empty() ? std::string("mesh") : input.source;
    if (!std::isfinite(spacing) || spacing <= 0) throw InputError(src + ": spacing r0 must be positive");
    if (!std::isfinite(support_radius) || support_radius <= 0) throw InputError(src + ": support radius h must be positive");
    const auto t_all = Clock::now();
    SolidSample out;
    out.spacing = spacing;
    out.support_radius = support_radius;

    auto t0 = Clock::now();
    validate_mesh(input, true);
    TriangleMesh mesh = input;
    SampleStats& st = out.stats;
    st.mesh_volume = signed_volume(mesh);
    if (st.mesh_volume < 0) {
        flip_orientation(mesh);
        st.mesh_volume = -st.mesh_volume;
        st.flipped = true;
    }
    const Vec3d extent = bounding_box(mesh).extent();
    if (spacing > extent.maxCoeff()) {
        // Every axis would hold a single lattice point (at the centre), and the rays cast along
        // the lattice lines start a spacing away: a spacing of 1e20 for a 1 m mesh puts them
        // beyond the single-precision range of the ray tracer.
        std::ostringstream s;
        s << src << ": spacing r0 = " << spacing << " is larger than the mesh itself (bounding box " << extent.x()
          << " x " << extent.y() << " x " << extent.z() << "); use a spacing below its largest side";
        throw InputError(s.str());
    }
    const double points = (extent.x() / spacing + 1) * (extent.y() / spacing + 1) * (extent.z() / spacing + 1);
    if (points > 2e9) {
        std::ostringstream s;
        s << src << ": spacing " << spacing << " is too fine for a mesh of size " << extent.x() << " x " << extent.y()
          << " x " << extent.z() << " (" << points << " lattice points)";
        throw InputError(s.str());
    }
    if (extent.norm() > kMaxSpacingsAcrossMesh * spacing) {
        std::ostringstream s;
        s << src << ": spacing r0 = " << spacing << " is too fine for the single-precision ray tracer: the mesh's "
          << "diagonal " << extent.norm() << " spans " << extent.norm() / spacing << " spacings, at most "
          << kMaxSpacingsAcrossMesh << " are allowed (crossings are located to about 1e-6 of the mesh's size)";
        throw InputError(s.str());
    }
    const EdgeReport edges = edge_report(mesh);
    st.boundary_edges = edges.boundary_edges;
    st.closed = edges.closed();
    st.triangles = mesh.triangles.size();
    st.mesh_area = surface_area(mesh);
    out.timings.prepare = since(t0);

    t0 = Clock::now();
    out.ibp = sample_inner(mesh, spacing, options.inside);
    out.timings.inner = since(t0);
    out.timings.embree = out.ibp.classification.build_seconds;
    out.timings.refine = out.ibp.classification.refine_seconds;

    t0 = Clock::now();
    out.sbp = sample_surface(mesh, spacing, options.surface);
    out.timings.surface = since(t0);

    t0 = Clock::now();
    if (options.geometry_max_edge > 0) {
        const RefinedMesh refined = refine_long_edges(mesh, options.geometry_max_edge * spacing);
        for (std::size_t k = 0; k < out.sbp.count(); ++k) refined.locate(out.sbp.triangles[k], out.sbp.barycentric[k]);
        out.geometry = refined.mesh;
    } else {
        out.geometry = mesh;
    }
    out.gp = link_geometry(out.geometry, out.ibp.positions, support_radius);
    out.timings.geometry = since(t0);
    out.timings.total = since(t_all);

    st.ibp_count = out.ibp.count();
    st.sbp_count = out.sbp.count();
    st.gp_count = out.gp.count();
    st.geometry_triangles = out.geometry.triangles.size();
    st.ibp_volume = double(st.ibp_count) * spacing * spacing * spacing;
    st.ambiguous_points = out.ibp.classification.ambiguous;
    st.refined_points = out.ibp.classification.refined;
    st.ray_directions = out.ibp.classification.directions_used;
    st.rays = out.ibp.classification.rays;
    st.sbp_candidates = out.sbp.candidates;
    st.sbp_filled = out.sbp.filled;
    st.gps_without_ibp = out.gp.without_ibp_in_h;
    st.ibp_links_total = out.gp.ibp.size();
    st.ibp_links_per_gp_min = out.gp.count() ? std::size_t(-1) : 0;
    for (std::size_t g = 0; g < out.gp.count(); ++g)
        st.ibp_links_per_gp_min = std::min(st.ibp_links_per_gp_min, std::size_t(out.gp.offsets[g + 1] - out.gp.offsets[g]));

    if (options.measure_coverage) {
        t0 = Clock::now();
        const double want = options.coverage_probes_per_r0sq * st.mesh_area / (spacing * spacing);
        const std::size_t probes = std::clamp(static_cast<std::size_t>(want), options.coverage_min_probes,
                                              std::max(options.coverage_min_probes, options.coverage_max_probes));
        const CoverageReport cov = measure_coverage(mesh, out.sbp.positions, probes);
        st.largest_gap = cov.largest_gap;
        st.mean_gap = cov.mean_gap;
        st.coverage_probes = cov.probes;
        out.timings.coverage = since(t0);
    }
    return out;
}

}  // namespace mw
