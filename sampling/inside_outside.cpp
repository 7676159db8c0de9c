#include "sampling/inside_outside.hpp"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <new>
#include <sstream>
#include <stdexcept>
#include <string>

#include <embree3/rtcore.h>
#include <omp.h>

#include "common/errors.hpp"
#include "sampling/embree_mesh.hpp"
#include "sampling/first_exception.hpp"
#include "sampling/winding_number.hpp"

namespace mw {

namespace {

struct Crossing {
    double t;
    int sign;
};

struct RawHit {
    float t;
    unsigned prim;
};

// RTCIntersectContext must be the first member: the filter gets a pointer to it.
struct HitCollector {
    RTCIntersectContext context;
    std::vector<RawHit>* hits;
    // Embree catches whatever a filter throws and carries on with the ray, so a failed push_back
    // would silently lose crossings: it is flagged here and raised by the caster instead.
    bool out_of_memory;
};

void collect_all_hits(const RTCFilterFunctionNArguments* args) {
    HitCollector* collector = reinterpret_cast<HitCollector*>(args->context);
    for (unsigned i = 0; i < args->N; ++i) {
        if (args->valid[i] == 0) continue;
        args->valid[i] = 0;  // reject, so traversal goes on and reports every hit
        if (collector->out_of_memory) continue;
        try {
            collector->hits->push_back({RTCRayN_tfar(args->ray, args->N, i), RTCHitN_primID(args->hit, args->N, i)});
        } catch (const std::bad_alloc&) {
            collector->out_of_memory = true;
        }
    }
}

// Largest distance from the mesh, in units of its bounding-box diagonal, at which a ray may start.
// Coordinates are handed to Embree in those units, so this keeps every ray far inside the float
// range (Embree asserts |origin| < 1.8e18) while allowing any line a caller can sensibly ask for.
constexpr double kMaxRayStart = 1e6;

// The ray caster over one mesh (embree_mesh.hpp holds the Embree scene and its coordinates).
class EmbreeScene {
public:
    explicit EmbreeScene(const TriangleMesh& mesh) : embree_(mesh, collect_all_hits) {
        normals_.resize(mesh.triangles.size());
        for (std::size_t t = 0; t < mesh.triangles.size(); ++t) normals_[t] = triangle_normal(mesh, t);
    }

    double reach() const { return embree_.reach(); }

    // Casts the infinite line through `through` along unit `dir`, starting `back` before it, and
    // returns its surface crossings (t measured from the start) with merged duplicate hits.
    void cast_line(const Vec3d& through, const Vec3d& dir, double back, bool parity, std::vector<RawHit>& hits,
                   std::vector<Crossing>& out) const {
        hits.clear();
        out.clear();
        const double reach = embree_.reach(), unit = embree_.unit();
        // The same operations, in the same order, as before EmbreeMesh was split out: a ray
        // origin rounded otherwise could change a crossing at a vertex.
        const Vec3d org = (through - embree_.center() - back * dir) / unit;
        if (!org.allFinite() || org.cwiseAbs().maxCoeff() > kMaxRayStart * reach / unit) {
            std::ostringstream s;
            s << "inside/outside test: a ray would start " << (through - embree_.center()).norm() + back
              << " from the centre of a mesh of size " << reach << ", beyond what the single-precision ray tracer handles";
            throw InputError(s.str());
        }
        RTCRayHit rh = embree_ray(org, dir, 0.f, std::numeric_limits<float>::infinity());
        HitCollector collector;
        rtcInitIntersectContext(&collector.context);
        collector.hits = &hits;
        collector.out_of_memory = false;
        rtcIntersect1(embree_.scene(), &collector.context, &rh);
        if (collector.out_of_memory) throw std::bad_alloc();
        // A hit at an infinite or NaN distance (the triangle test overflowed) locates nothing, and
        // NaN would also break the ordering below: such hits are dropped.
        hits.erase(std::remove_if(hits.begin(), hits.end(), [](const RawHit& h) { return !std::isfinite(h.t); }),
                   hits.end());
        if (hits.empty()) return;
        // Order by t, then drop repeated reports of one triangle (a BVH may list it twice).
        std::sort(hits.begin(), hits.end(), [](const RawHit& a, const RawHit& b) {
            return a.t < b.t || (a.t == b.t && a.prim < b.prim);
        });
        const double eps = 1e-6 * reach;
        auto distance = [&](std::size_t k) { return double(hits[k].t) * unit; };
        auto sign_of = [&](std::size_t k) {
            const double c = normals_[hits[k].prim].dot(dir);
            return c > 0 ? 1 : (c < 0 ? -1 : 0);
        };
        std::size_t i = 0;
        while (i < hits.size()) {
            // Group hits within eps of the first: one crossing of an edge or vertex. The group
            // always holds hits[i], so every pass consumes at least one hit.
            int sum = sign_of(i);
            std::size_t j = i + 1;
            for (; j < hits.size() && distance(j) - distance(i) <= eps; ++j) {
                bool repeated = false;
                for (std::size_t k = i; k < j; ++k) repeated = repeated || hits[k].prim == hits[j].prim;
                if (!repeated) sum += sign_of(j);
            }
            const double t = 0.5 * (distance(i) + distance(j - 1));
            if (parity)
                out.push_back({t, 1});
            else if (sum != 0)
                out.push_back({t, sum > 0 ? 1 : -1});
            i = j;
        }
    }

private:
    EmbreeMesh embree_;
    std::vector<Vec3d> normals_;
};

// Lattice line directions: axes, body diagonals, face diagonals (one per opposite pair).
const int kFamilies[13][3] = {{1, 0, 0},  {0, 1, 0},  {0, 0, 1},  {1, 1, 1},  {1, 1, -1}, {1, -1, 1}, {-1, 1, 1},
                              {1, 1, 0},  {1, -1, 0}, {1, 0, 1},  {1, 0, -1}, {0, 1, 1},  {0, 1, -1}};

int resolve_families(int requested, bool closed) {
    if (requested == 0) return closed ? 3 : 13;
    if (requested <= 3) return 3;
    if (requested <= 7) return 7;
    return 13;
}

}  // namespace

InsideOutsideResult classify_lattice(const TriangleMesh& mesh, const LatticeGrid& grid, const InsideOutsideOptions& options) {
    InsideOutsideResult result;
    const EdgeReport edges = edge_report(mesh);
    result.parity = !edges.consistently_oriented();
    result.directions_used = resolve_families(options.directions, edges.closed());
    const auto t0 = std::chrono::steady_clock::now();
    EmbreeScene scene(mesh);
    result.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

    const std::size_t n = grid.count();
    std::vector<std::int16_t> votes(n, 0);    // sum of winding samples
    std::vector<std::uint8_t> positive(n, 0);  // samples saying "inside"
    const double back = scene.reach() + grid.spacing;
    std::size_t rays = 0;
    for (int f = 0; f < result.directions_used; ++f) {
        const int dx = kFamilies[f][0], dy = kFamilies[f][1], dz = kFamilies[f][2];
        const Vec3d dir = Vec3d(dx, dy, dz).normalized();
        const double step = grid.spacing * std::sqrt(double(dx * dx + dy * dy + dz * dz));
        // Lines start at lattice points whose predecessor along d lies outside the grid.
        std::vector<std::array<int, 3>> starts;
        for (int k = 0; k < grid.dims[2]; ++k)
            for (int j = 0; j < grid.dims[1]; ++j)
                for (int i = 0; i < grid.dims[0]; ++i)
                    if (!grid.contains(i - dx, j - dy, k - dz)) starts.push_back({i, j, k});
        rays += starts.size();
        FirstException failure;
#pragma omp parallel
        {
            std::vector<RawHit> hits;
            std::vector<Crossing> crossings;
#pragma omp for schedule(dynamic, 16)
            for (long s = 0; s < static_cast<long>(starts.size()); ++s) failure.run([&] {
                const auto p0 = starts[static_cast<std::size_t>(s)];
                scene.cast_line(grid.position(p0[0], p0[1], p0[2]), dir, back, result.parity, hits, crossings);
                int total = 0;
                for (const Crossing& c : crossings) total += c.sign;
                int before = 0;
                std::size_t c = 0;
                int i = p0[0], j = p0[1], k = p0[2];
                for (int m = 0; grid.contains(i, j, k); ++m, i += dx, j += dy, k += dz) {
                    const double t = back + m * step;
                    while (c < crossings.size() && crossings[c].t < t) before += crossings[c++].sign;
                    int w_plus = total - before, w_minus = -before;
                    if (result.parity) {
                        w_plus = (total - before) & 1;
                        w_minus = before & 1;
                    }
                    const std::size_t id = grid.index(i, j, k);
                    votes[id] = static_cast<std::int16_t>(votes[id] + w_plus + w_minus);
                    positive[id] = static_cast<std::uint8_t>(positive[id] + (w_plus > 0) + (w_minus > 0));
                }
            });
        }
        failure.rethrow();
    }
    result.rays = rays;
    const int samples = 2 * result.directions_used;
    result.inside.resize(n);
    std::size_t ambiguous = 0;
    std::vector<std::size_t> undecided;
    const bool refine = !edges.closed() && !result.parity && options.refine_band > 0;
    for (std::size_t id = 0; id < n; ++id) {
        result.inside[id] = 2 * votes[id] > samples ? 1 : 0;
        if (positive[id] != 0 && positive[id] != samples) ++ambiguous;
        if (refine && std::abs(double(votes[id]) / samples - 0.5) <= options.refine_band) undecided.push_back(id);
    }
    result.ambiguous = ambiguous;
    if (!undecided.empty()) {
        // Open mesh: the vote estimates the winding number to a few hundredths; where it is close
        // to 1/2 ask the winding number itself (fast, exact near 1/2).
        const auto t_refine = std::chrono::steady_clock::now();
        const FastWindingNumber wn(mesh);
        const std::size_t nx = std::size_t(grid.dims[0]), ny = std::size_t(grid.dims[1]);
        FirstException failure;
#pragma omp parallel for schedule(dynamic, 32)
        for (long u = 0; u < static_cast<long>(undecided.size()); ++u) failure.run([&] {
            const std::size_t id = undecided[static_cast<std::size_t>(u)];
            const int i = int(id % nx), j = int((id / nx) % ny), k = int(id / (nx * ny));
            result.inside[id] = wn.evaluate_exact_near_half(grid.position(i, j, k)) > 0.5 ? 1 : 0;
        });
        failure.rethrow();
        result.refined = undecided.size();
        result.refine_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_refine).count();
    }
    return result;
}

std::vector<std::uint8_t> classify_points(const TriangleMesh& mesh, const std::vector<Vec3d>& points, int directions,
                                          double refine_band) {
    const EdgeReport edges = edge_report(mesh);
    const bool parity = !edges.consistently_oriented();
    const int families = resolve_families(directions, edges.closed());
    EmbreeScene scene(mesh);
    const Vec3d center = bounding_box(mesh).center();
    const double reach = scene.reach();
    std::vector<std::uint8_t> inside(points.size(), 0);
    std::unique_ptr<FastWindingNumber> wn;
    if (!edges.closed() && !parity && refine_band > 0) wn = std::make_unique<FastWindingNumber>(mesh);
    FirstException failure;
#pragma omp parallel
    {
        std::vector<RawHit> hits;
        std::vector<Crossing> crossings;
#pragma omp for schedule(dynamic, 64)
        for (long p = 0; p < static_cast<long>(points.size()); ++p) failure.run([&] {
            const Vec3d& q = points[static_cast<std::size_t>(p)];
            int votes = 0;
            for (int f = 0; f < families; ++f) {
                const Vec3d dir = Vec3d(kFamilies[f][0], kFamilies[f][1], kFamilies[f][2]).normalized();
                // The line through q is cast from its point nearest the mesh's centre, `reach`
                // before it (outside the bounding box), so that however far q lies the ray starts
                // near the mesh; q sits at t_q along it. A line passing farther than `reach` from
                // the centre misses the bounding box and crosses nothing.
                const double along = (q - center).dot(dir);
                const Vec3d foot = q - along * dir;
                const double t_q = reach + along;
                crossings.clear();
                if ((foot - center).norm() <= reach) scene.cast_line(foot, dir, reach, parity, hits, crossings);
                int total = 0, before = 0;
                for (const Crossing& c : crossings) {
                    total += c.sign;
                    if (c.t < t_q) before += c.sign;
                }
                votes += parity ? (((total - before) & 1) + (before & 1)) : (total - before) + (-before);
            }
            inside[static_cast<std::size_t>(p)] = votes > families ? 1 : 0;  // mean of 2F samples > 1/2
            if (wn && std::abs(double(votes) / (2 * families) - 0.5) <= refine_band)
                inside[static_cast<std::size_t>(p)] = wn->evaluate_exact_near_half(q) > 0.5 ? 1 : 0;
        });
    }
    failure.rethrow();
    return inside;
}

double winding_number(const TriangleMesh& mesh, const Vec3d& p) {
    double sum = 0;
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        const Vec3d a = mesh.corner(t, 0) - p, b = mesh.corner(t, 1) - p, c = mesh.corner(t, 2) - p;
        const double la = a.norm(), lb = b.norm(), lc = c.norm();
        const double num = a.dot(b.cross(c));
        const double den = la * lb * lc + a.dot(b) * lc + a.dot(c) * lb + b.dot(c) * la;
        sum += 2.0 * std::atan2(num, den);
    }
    return sum / (4.0 * M_PI);
}

}  // namespace mw
