#include "sampling/outline_sample.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "common/errors.hpp"
#include "sampling/outline.hpp"

namespace mw {

namespace {

// An edge a whole number of spacings long stays that many pieces when the spacing is a float
// (a scene's r0 of 0.01 is 0.0099999998): counts are rounded up past this share of one.
constexpr double kRounding = 1e-4;

// The outline's edges split to at most `max_edge` (the corners keep their indices), oriented
// with the solid on the left.
TriangleMesh refine_outline(const TriangleMesh& outline, double max_edge) {
    TriangleMesh refined;
    refined.source = outline.source;
    refined.vertices = outline.vertices;
    for (const auto& e : oriented_outline_edges(outline)) {
        const Vec3d a = outline.vertices[std::size_t(e[0])], b = outline.vertices[std::size_t(e[1])];
        const int pieces = max_edge > 0 ? std::max(1, int(std::ceil((b - a).norm() / max_edge - kRounding))) : 1;
        int previous = e[0];
        for (int k = 1; k <= pieces; ++k) {
            int next = e[1];
            if (k < pieces) {
                next = int(refined.vertices.size());
                refined.vertices.push_back(a + (double(k) / pieces) * (b - a));
            }
            refined.triangles.push_back({previous, next, previous});
            previous = next;
        }
    }
    return refined;
}

// The lattice points inside the outline, with their one-ring (8 neighbours in the plane).
InnerParticles inner_lattice(const TriangleMesh& outline, double spacing) {
    InnerParticles ibp;
    Aabb box = bounding_box(outline);
    ibp.grid = make_lattice_grid(box, spacing);
    const std::vector<std::array<int, 2>> edges = outline_edges(outline);
    const int nx = ibp.grid.dims[0], ny = ibp.grid.dims[1];
    std::vector<int> index(std::size_t(nx) * std::size_t(ny), -1);
    std::vector<double> crossings;
    for (int j = 0; j < ny; ++j) {
        // A row at a time, by the even-odd rule of inside_outline: a point is inside when an odd
        // number of the edges cross its row to its right.
        const double y = ibp.grid.position(0, j, 0).y();
        crossings.clear();
        for (const auto& e : edges) {
            const Vec3d& a = outline.vertices[std::size_t(e[0])];
            const Vec3d& b = outline.vertices[std::size_t(e[1])];
            if ((a.y() > y) != (b.y() > y)) crossings.push_back(a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y()));
        }
        std::sort(crossings.begin(), crossings.end());
        for (int i = 0; i < nx; ++i) {
            const Vec3d x = ibp.grid.position(i, j, 0);
            const auto right = crossings.end() - std::upper_bound(crossings.begin(), crossings.end(), x.x());
            if (right % 2 == 0) continue;
            index[std::size_t(j) * std::size_t(nx) + std::size_t(i)] = int(ibp.positions.size());
            ibp.positions.push_back(x);
            ibp.lattice.push_back({i, j, 0});
        }
    }
    ibp.neighbor_offsets.assign(1, 0);
    for (const auto& c : ibp.lattice) {
        for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
                const int i = c[0] + di, j = c[1] + dj;
                if ((di == 0 && dj == 0) || i < 0 || j < 0 || i >= nx || j >= ny) continue;
                const int q = index[std::size_t(j) * std::size_t(nx) + std::size_t(i)];
                if (q >= 0) ibp.neighbor_indices.push_back(q);
            }
        std::sort(ibp.neighbor_indices.begin() + ibp.neighbor_offsets.back(), ibp.neighbor_indices.end());
        ibp.neighbor_offsets.push_back(int(ibp.neighbor_indices.size()));
    }
    return ibp;
}

// One SBP per `spacing` of each refined edge, at least one, spread evenly along it.
SurfaceParticles outline_surface(const TriangleMesh& geometry, double spacing) {
    SurfaceParticles sbp;
    for (std::size_t t = 0; t < geometry.triangles.size(); ++t) {
        const Vec3d a = geometry.corner(t, 0), b = geometry.corner(t, 1);
        const Vec3d d = b - a;
        const Vec3d normal = Vec3d(d.y(), -d.x(), 0).normalized();
        const int count = std::max(1, int(std::ceil(d.norm() / spacing - kRounding)));
        for (int k = 0; k < count; ++k) {
            const double f = (k + 0.5) / count;
            sbp.positions.push_back(a + f * d);
            sbp.normals.push_back(normal);
            sbp.triangles.push_back(int(t));
            sbp.barycentric.emplace_back(1 - f, f, 0);
        }
    }
    sbp.candidates = sbp.positions.size();
    return sbp;
}

}  // namespace

SolidSample sample_outline(const TriangleMesh& outline, double spacing, double support_radius, const OutlineSampleOptions& options) {
    const std::string src = outline.source.empty() ? std::string("outline") : outline.source;
    if (!std::isfinite(spacing) || spacing <= 0) throw InputError(src + ": spacing r0 must be positive");
    if (!std::isfinite(support_radius) || support_radius <= 0) throw InputError(src + ": support radius h must be positive");
    if (!is_outline(outline)) throw InputError(src + ": not an outline (a 2D object's shape is closed loops of edges)");
    if (!(options.surface_spacing > 0)) throw InputError(src + ": the SBPs' spacing must be positive");
    const Vec3d extent = bounding_box(outline).extent();
    // The lattice's index takes 4 bytes a cell of the outline's bounding box.
    if ((extent.x() / spacing + 1) * (extent.y() / spacing + 1) > 1e8) {
        std::ostringstream s;
        s << src << ": spacing " << spacing << " is too fine for an outline of size " << extent.x() << " x " << extent.y();
        throw InputError(s.str());
    }
    SolidSample out;
    out.spacing = spacing;
    out.support_radius = support_radius;
    out.ibp = inner_lattice(outline, spacing);
    out.geometry = refine_outline(outline, options.geometry_max_edge * spacing);
    out.sbp = outline_surface(out.geometry, options.surface_spacing * spacing);
    out.gp = link_geometry(out.geometry, out.ibp.positions, support_radius);
    SampleStats& st = out.stats;
    st.ibp_count = out.ibp.count();
    st.sbp_count = out.sbp.count();
    st.gp_count = out.gp.count();
    st.triangles = outline.triangles.size();
    st.geometry_triangles = out.geometry.triangles.size();
    st.closed = true;
    st.mesh_volume = outline_area(outline);  // per unit depth: an area
    for (std::size_t t = 0; t < out.geometry.triangles.size(); ++t)
        st.mesh_area += (out.geometry.corner(t, 1) - out.geometry.corner(t, 0)).norm();
    st.ibp_volume = double(st.ibp_count) * spacing * spacing;
    st.gps_without_ibp = out.gp.without_ibp_in_h;
    st.ibp_links_total = out.gp.ibp.size();
    return out;
}

std::vector<double> outline_insets(const TriangleMesh& geometry, const SurfaceParticles& sbp, double depth) {
    std::vector<double> inset(sbp.count(), depth);
    for (std::size_t k = 0; k < sbp.count(); ++k) {
        const Vec3d p = sbp.positions[k], inward = -sbp.normals[k];
        double nearest = INFINITY;
        for (std::size_t t = 0; t < geometry.triangles.size(); ++t) {
            if (int(t) == sbp.triangles[k]) continue;
            const Vec3d a = geometry.corner(t, 0), e = geometry.corner(t, 1) - a;
            // p + s inward = a + u e, s > 0, u in [0, 1].
            const double det = inward.y() * e.x() - inward.x() * e.y();
            if (det == 0) continue;
            const Vec3d w = a - p;
            const double s = (w.y() * e.x() - w.x() * e.y()) / det;
            const double u = (inward.x() * w.y() - inward.y() * w.x()) / det;
            if (s > 0 && u >= 0 && u <= 1) nearest = std::min(nearest, s);
        }
        if (std::isfinite(nearest)) inset[k] = std::min(depth, 0.5 * nearest);
    }
    return inset;
}

}  // namespace mw
