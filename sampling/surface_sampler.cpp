#include "sampling/surface_sampler.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <unordered_map>

#include "common/errors.hpp"
#include "sampling/kdtree.hpp"

namespace mw {

namespace {

// Kept SBPs in a uniform grid of cells (linked lists), for the sequential thinning passes.
class CellGrid {
public:
    CellGrid(const Aabb& box, double cell) {
        const Vec3d e = box.extent();
        for (;;) {
            for (int a = 0; a < 3; ++a) dims_[a] = std::max(1L, static_cast<long>(std::ceil(e[a] / cell)) + 1);
            if (double(dims_[0]) * double(dims_[1]) * double(dims_[2]) <= double(1 << 26)) break;
            cell *= 1.5;  // keep the head array bounded for huge meshes at tiny spacing
        }
        cell_ = cell;
        lo_ = box.lo - Vec3d::Constant(0.5 * cell);
        head_.assign(static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]), -1);
    }
    double cell() const { return cell_; }
    void insert(int id, const Vec3d& p) {
        const long c = cell_of(p);
        if (static_cast<std::size_t>(id) >= next_.size()) next_.resize(static_cast<std::size_t>(id) + 1, -1);
        next_[static_cast<std::size_t>(id)] = head_[static_cast<std::size_t>(c)];
        head_[static_cast<std::size_t>(c)] = id;
    }
    // Calls f(id) for every inserted id in the cells within `radius` (<= cell) of p until f returns true.
    template <class F>
    bool any_near(const Vec3d& p, F&& f) const {
        long c[3];
        for (int a = 0; a < 3; ++a) c[a] = coord(p, a);
        for (long z = std::max(0L, c[2] - 1); z <= std::min(dims_[2] - 1, c[2] + 1); ++z)
            for (long y = std::max(0L, c[1] - 1); y <= std::min(dims_[1] - 1, c[1] + 1); ++y)
                for (long x = std::max(0L, c[0] - 1); x <= std::min(dims_[0] - 1, c[0] + 1); ++x)
                    for (int id = head_[static_cast<std::size_t>((z * dims_[1] + y) * dims_[0] + x)]; id >= 0;
                         id = next_[static_cast<std::size_t>(id)])
                        if (f(id)) return true;
        return false;
    }

private:
    long coord(const Vec3d& p, int a) const {
        return std::clamp(static_cast<long>(std::floor((p[a] - lo_[a]) / cell_)), 0L, dims_[a] - 1);
    }
    long cell_of(const Vec3d& p) const { return (coord(p, 2) * dims_[1] + coord(p, 1)) * dims_[0] + coord(p, 0); }
    long dims_[3];
    double cell_;
    Vec3d lo_;
    std::vector<int> head_, next_;
};

std::uint64_t mix64(std::uint64_t x) {  // splitmix64 finaliser
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    return x ^ (x >> 31);
}

struct Candidate {
    Vec3d position;
    Vec3d bary;
    int triangle;
};

}  // namespace

SurfaceParticles sample_surface(const TriangleMesh& mesh, double spacing, const SurfaceOptions& options) {
    SurfaceParticles out;
    const double g = options.candidate_gap * spacing;
    const double rho = options.min_distance * spacing;
    const double fill = std::max(0.0, (options.coverage - options.candidate_gap) * spacing);
    const std::size_t nt = mesh.triangles.size();
    const std::string src = mesh.source.empty() ? std::string("mesh") : mesh.source;
    // Triangles and candidates are numbered with 32-bit ints.
    if (nt > (std::size_t(1) << 31))
        throw InputError(src + ": " + std::to_string(nt) + " triangles, more than the surface sampler handles (2^31)");

    // 1. Candidates: sub-grid vertices of every non-degenerate triangle. Points shared between
    // triangles are emitted once: a mesh vertex by its first triangle, the inner points of an edge
    // by its first triangle when the neighbour subdivides the edge the same way (same m, so the
    // same points); otherwise by both. The candidate set is the union of all sub-grids either way.
    std::vector<int> subdiv(nt, 0);
    std::vector<std::uint8_t> owns(nt, 0);  // bits 0-2: corners, bits 3-5: edges k -> k+1
    std::vector<Vec3d> normals;
    normals.reserve(mesh.triangles.size());
    for (std::size_t t = 0; t < nt; ++t) {
        normals.push_back(triangle_normal(mesh, t));
        if (normals[t].squaredNorm() == 0) continue;  // degenerate: covered by its neighbours
        const double L = std::max({(mesh.corner(t, 1) - mesh.corner(t, 0)).norm(), (mesh.corner(t, 2) - mesh.corner(t, 1)).norm(),
                                   (mesh.corner(t, 0) - mesh.corner(t, 2)).norm()});
        subdiv[t] = std::max(1, static_cast<int>(std::ceil(L / (std::sqrt(3.0) * g))));
    }
    {
        std::vector<std::uint8_t> vertex_done(mesh.vertices.size(), 0);
        std::unordered_map<std::uint64_t, int> edge_m;
        edge_m.reserve(nt * 2);
        for (std::size_t t = 0; t < nt; ++t) {
            if (subdiv[t] == 0) continue;
            const auto& tri = mesh.triangles[t];
            for (int k = 0; k < 3; ++k) {
                if (!vertex_done[static_cast<std::size_t>(tri[k])]) {
                    vertex_done[static_cast<std::size_t>(tri[k])] = 1;
                    owns[t] |= std::uint8_t(1u << k);
                }
                std::uint64_t a = static_cast<std::uint32_t>(tri[k]), b = static_cast<std::uint32_t>(tri[(k + 1) % 3]);
                if (a > b) std::swap(a, b);
                const auto ins = edge_m.emplace((a << 32) | b, subdiv[t]);
                if (ins.second || ins.first->second != subdiv[t]) owns[t] |= std::uint8_t(8u << k);
            }
        }
    }
    // Which sub-grid point (i, j) of an m-subdivided triangle to emit.
    auto emits = [](int i, int j, int m, std::uint8_t own) {
        if (i == 0 && j == 0) return (own & 1) != 0;
        if (i == m && j == 0) return (own & 2) != 0;
        if (i == 0 && j == m) return (own & 4) != 0;
        if (j == 0) return (own & 8) != 0;       // edge corner 0 -> 1
        if (i + j == m) return (own & 16) != 0;  // edge corner 1 -> 2
        if (i == 0) return (own & 32) != 0;      // edge corner 2 -> 0
        return true;
    };
    std::vector<std::size_t> first(nt + 1, 0);
#pragma omp parallel for schedule(static)
    for (long tl = 0; tl < static_cast<long>(nt); ++tl) {
        const auto t = static_cast<std::size_t>(tl);
        const int m = subdiv[t];
        if (m == 0) continue;
        std::size_t n = static_cast<std::size_t>(m - 1) * static_cast<std::size_t>(m - 2) / 2;  // interior
        for (int k = 0; k < 3; ++k) n += ((owns[t] >> k) & 1) + ((owns[t] >> (3 + k)) & 1) * std::size_t(m - 1);
        first[t + 1] = n;
    }
    std::partial_sum(first.begin(), first.end(), first.begin());
    const std::size_t total = first[nt];
    if (total > (std::size_t(1) << 31)) {
        std::ostringstream msg;
        msg << src << ": the surface needs " << total << " candidate points at spacing r0 = " << spacing
            << ", more than the surface sampler handles (2^31); use a coarser spacing";
        throw InputError(msg.str());
    }
    std::vector<Candidate> cand;
    cand.resize(total);
#pragma omp parallel for schedule(dynamic, 256)
    for (long tl = 0; tl < static_cast<long>(nt); ++tl) {
        const auto t = static_cast<std::size_t>(tl);
        const int m = subdiv[t];
        if (m == 0) continue;
        std::size_t at = first[t];
        for (int j = 0; j <= m; ++j)
            for (int i = 0; i + j <= m; ++i) {
                if (!emits(i, j, m, owns[t])) continue;
                const double b1 = double(i) / m, b2 = double(j) / m;
                const Vec3d bary(1.0 - b1 - b2, b1, b2);
                cand[at++] = {surface_position(mesh, static_cast<int>(t), bary), bary, static_cast<int>(t)};
            }
    }
    out.candidates = cand.size();

    // Processing order: cells of size min_distance in a pseudo-random order, candidates in a
    // pseudo-random order inside each cell. As random as a full shuffle for the thinning (the
    // result has the same density) but several times faster: consecutive candidates share their
    // neighbour cells in cache.
    const Aabb box = bounding_box(mesh);
    const double order_cell = std::max(rho, 1e-3 * spacing);
    std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(cand.size());
#pragma omp parallel for schedule(static)
    for (long i = 0; i < static_cast<long>(cand.size()); ++i) {
        const Vec3d q = (cand[static_cast<std::size_t>(i)].position - box.lo) / order_cell;
        std::uint64_t cell = 0;
        for (int a = 0; a < 3; ++a) cell = cell * 0x100000ull + (static_cast<std::uint64_t>(std::max(0.0, q[a])) & 0xFFFFFull);
        const std::uint64_t key = (mix64(cell ^ options.seed) & ~((1ull << 20) - 1)) |
                                  (mix64(static_cast<std::uint64_t>(i) + 0x5851F42D4C957F2Dull * options.seed) & ((1ull << 20) - 1));
        keyed[static_cast<std::size_t>(i)] = {key, static_cast<std::uint32_t>(i)};
    }
    std::sort(keyed.begin(), keyed.end());
    std::vector<std::uint32_t> order(cand.size());
    for (std::size_t i = 0; i < keyed.size(); ++i) order[i] = keyed[i].second;
    keyed = {};

    CellGrid grid(box, std::max(rho, fill));
    auto keep = [&](const Candidate& c) {
        const int id = static_cast<int>(out.positions.size());
        out.positions.push_back(c.position);
        out.normals.push_back(normals[static_cast<std::size_t>(c.triangle)]);
        out.triangles.push_back(c.triangle);
        out.barycentric.push_back(c.bary);
        grid.insert(id, c.position);
    };

    // 2. Poisson-disk thinning.
    const double rho2 = rho * rho;
    for (std::uint32_t idx : order) {
        const Candidate& c = cand[idx];
        const Vec3d& n = normals[static_cast<std::size_t>(c.triangle)];
        const bool blocked = grid.any_near(c.position, [&](int id) {
            const auto s = static_cast<std::size_t>(id);
            return (out.positions[s] - c.position).squaredNorm() < rho2 && (!options.two_sided || out.normals[s].dot(n) > -0.5);
        });
        if (!blocked) keep(c);
    }
    // 3. Gap filling: only needed when the thinning radius exceeds the fill distance (with
    // min_distance <= coverage - candidate_gap every candidate is already within reach).
    const std::size_t thinned = out.positions.size();
    const double fill2 = fill * fill;
    if (rho > fill * (1 + 1e-9)) {
        for (std::uint32_t idx : order) {
            const Candidate& c = cand[idx];
            const bool covered = grid.any_near(c.position, [&](int id) {
                return (out.positions[static_cast<std::size_t>(id)] - c.position).squaredNorm() <= fill2;
            });
            if (!covered) keep(c);
        }
    }
    out.filled = out.positions.size() - thinned;
    return out;
}

std::vector<SurfacePoint> random_surface_points(const TriangleMesh& mesh, std::size_t count, std::uint64_t seed) {
    const std::size_t nt = mesh.triangles.size();
    std::vector<double> cdf(nt);
    double acc = 0;
    for (std::size_t t = 0; t < nt; ++t) cdf[t] = (acc += triangle_area(mesh, t));
    std::vector<SurfacePoint> pts(count);
    if (count == 0 || !(acc > 0)) return {};
    const std::size_t chunk = 16384;
    const long chunks = static_cast<long>((count + chunk - 1) / chunk);
#pragma omp parallel for schedule(static)
    for (long c = 0; c < chunks; ++c) {
        std::mt19937_64 rng(seed * 0x9E3779B97F4A7C15ull + static_cast<std::uint64_t>(c));
        std::uniform_real_distribution<double> u01(0.0, 1.0);
        const std::size_t end = std::min(count, static_cast<std::size_t>(c + 1) * chunk);
        for (std::size_t i = static_cast<std::size_t>(c) * chunk; i < end; ++i) {
            const double r = u01(rng) * acc;
            std::size_t t = static_cast<std::size_t>(std::upper_bound(cdf.begin(), cdf.end(), r) - cdf.begin());
            t = std::min(t, nt - 1);
            const double s = std::sqrt(u01(rng)), v = u01(rng);
            const Vec3d bary(1.0 - s, s * (1.0 - v), s * v);
            pts[i] = {surface_position(mesh, static_cast<int>(t), bary), static_cast<int>(t), bary};
        }
    }
    return pts;
}

CoverageReport measure_coverage(const TriangleMesh& mesh, const std::vector<Vec3d>& sbp_positions, std::size_t probes,
                                std::uint64_t seed) {
    CoverageReport r;
    if (sbp_positions.empty()) {
        r.largest_gap = std::numeric_limits<double>::infinity();
        return r;
    }
    const std::vector<SurfacePoint> pts = random_surface_points(mesh, probes, seed);
    PointTree tree(sbp_positions);
    double largest = 0, sum = 0;
    long worst = 0;
#pragma omp parallel
    {
        double my_largest = 0;
        long my_worst = 0;
#pragma omp for reduction(+ : sum) schedule(static)
        for (long i = 0; i < static_cast<long>(pts.size()); ++i) {
            const double d = tree.nearest(pts[static_cast<std::size_t>(i)].position).second;
            sum += d;
            if (d > my_largest) {
                my_largest = d;
                my_worst = i;
            }
        }
#pragma omp critical
        if (my_largest > largest || (my_largest == largest && my_worst < worst)) {
            largest = my_largest;
            worst = my_worst;
        }
    }
    r.probes = pts.size();
    r.largest_gap = largest;
    r.mean_gap = pts.empty() ? 0 : sum / double(pts.size());
    if (!pts.empty()) r.worst_point = pts[static_cast<std::size_t>(worst)].position;
    return r;
}

}  // namespace mw
