#include "sampling/rod_sample.hpp"

#include <cmath>
#include <string>

#include "common/errors.hpp"

namespace mw {

namespace {

// The point at arc length s along the polyline (cumulative lengths `at`), s in [0, at.back()].
Vec3d point_along(const std::vector<Vec3d>& v, const std::vector<double>& at, double s) {
    std::size_t k = 1;
    while (k + 1 < at.size() && at[k] < s) ++k;
    const double span = at[k] - at[k - 1];
    const double t = span > 0 ? std::min(1.0, std::max(0.0, (s - at[k - 1]) / span)) : 0.0;
    return (1 - t) * v[k - 1] + t * v[k];
}

}  // namespace

RodSample sample_rod(const TriangleMesh& line, double spacing) {
    const std::string src = line.source.empty() ? std::string("mesh") : line.source;
    if (!std::isfinite(spacing) || spacing <= 0) throw InputError(src + ": spacing r0 must be positive");
    if (!line.triangles.empty())
        throw InputError(src + ": a rod is a line (procedural \"line:length=...\"), but this mesh has " +
                         std::to_string(line.triangles.size()) + " triangles");
    const std::vector<Vec3d>& v = line.vertices;
    if (v.size() < 2) throw InputError(src + ": a rod's line needs at least two points");
    for (std::size_t k = 0; k < v.size(); ++k)
        if (!v[k].allFinite()) throw InputError(src + ": point " + std::to_string(k + 1) + " is not finite");
    std::vector<double> at(v.size(), 0.0);
    for (std::size_t k = 1; k < v.size(); ++k) {
        const double step = (v[k] - v[k - 1]).norm();
        if (!(step > 0)) throw InputError(src + ": points " + std::to_string(k) + " and " + std::to_string(k + 1) + " coincide");
        at[k] = at[k - 1] + step;
    }
    RodSample out;
    out.length = at.back();
    // Equal steps of at most r0 (to a rounding's slack, so that a length of n r0 gives n steps).
    const std::size_t segments = static_cast<std::size_t>(std::ceil(out.length / spacing - 1e-6));
    if (segments < 2)
        throw InputError(src + ": the rod is " + std::to_string(out.length) + " m long, which gives " +
                         std::to_string(segments + 1) + " node(s) at spacing " + std::to_string(spacing) +
                         " m; a rod needs at least 3 (a length over r0)");
    const double step = out.length / double(segments);
    for (std::size_t k = 0; k <= segments; ++k) out.nodes.push_back(point_along(v, at, k == segments ? out.length : double(k) * step));
    const std::size_t n = out.nodes.size();
    out.node_length.assign(n, step);
    out.node_length.front() = out.node_length.back() = step / 2;
    out.graph_offsets.assign(1, 0);
    for (std::size_t k = 0; k < n; ++k) {
        if (k > 0) out.graph_links.push_back(std::uint32_t(k - 1));
        if (k + 1 < n) out.graph_links.push_back(std::uint32_t(k + 1));
        out.graph_offsets.push_back(std::uint32_t(out.graph_links.size()));
    }
    // Two per segment, at its quarter points: with the nodes, a line of boundary particles r0/2 apart
    // at the most.
    for (std::size_t s = 0; s + 1 < n; ++s)
        for (int j = 0; j < kRodSamplesPerSegment; ++j) {
            const double f = (double(j) + 0.5) / double(kRodSamplesPerSegment);
            out.sbp.push_back((1 - f) * out.nodes[s] + f * out.nodes[s + 1]);
            out.sbp_segment.push_back(std::uint32_t(s));
            out.sbp_fraction.push_back(f);
        }
    return out;
}

}  // namespace mw
