#include "sampling/outline.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <numeric>
#include <sstream>

#include "common/errors.hpp"
#include "sampling/procedural_meshes.hpp"

namespace mw {

namespace {

double cross2(const Vec3d& a, const Vec3d& b) { return a.x() * b.y() - a.y() * b.x(); }

// Whether segments pq and rs share a point (collinear overlaps included).
bool segments_meet(const Vec3d& p, const Vec3d& q, const Vec3d& r, const Vec3d& s) {
    const double d1 = cross2(q - p, r - p), d2 = cross2(q - p, s - p);
    const double d3 = cross2(s - r, p - r), d4 = cross2(s - r, q - r);
    if (((d1 > 0 && d2 < 0) || (d1 < 0 && d2 > 0)) && ((d3 > 0 && d4 < 0) || (d3 < 0 && d4 > 0))) return true;
    const auto on = [](const Vec3d& a, const Vec3d& b, const Vec3d& c, double d) {
        return d == 0 && std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) &&
               std::min(a.y(), b.y()) <= c.y() && c.y() <= std::max(a.y(), b.y());
    };
    return on(p, q, r, d1) || on(p, q, s, d2) || on(r, s, p, d3) || on(r, s, q, d4);
}

// Edges that cross or touch anywhere but at a shared corner: a sweep along x.
void check_simple(const TriangleMesh& m, const std::vector<std::array<int, 2>>& edges) {
    std::vector<std::size_t> order(edges.size());
    std::iota(order.begin(), order.end(), std::size_t(0));
    const auto lo_x = [&](std::size_t e) { return std::min(m.vertices[edges[e][0]].x(), m.vertices[edges[e][1]].x()); };
    const auto hi_x = [&](std::size_t e) { return std::max(m.vertices[edges[e][0]].x(), m.vertices[edges[e][1]].x()); };
    std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return lo_x(a) < lo_x(b); });
    for (std::size_t i = 0; i < order.size(); ++i) {
        const auto& e = edges[order[i]];
        for (std::size_t j = i + 1; j < order.size() && lo_x(order[j]) <= hi_x(order[i]); ++j) {
            const auto& f = edges[order[j]];
            if (e[0] == f[0] || e[0] == f[1] || e[1] == f[0] || e[1] == f[1]) continue;
            if (segments_meet(m.vertices[e[0]], m.vertices[e[1]], m.vertices[f[0]], m.vertices[f[1]])) {
                std::ostringstream s;
                s << m.source << ": edges (" << m.vertices[e[0]].x() << ", " << m.vertices[e[0]].y() << ")-("
                  << m.vertices[e[1]].x() << ", " << m.vertices[e[1]].y() << ") and (" << m.vertices[f[0]].x() << ", "
                  << m.vertices[f[0]].y() << ")-(" << m.vertices[f[1]].x() << ", " << m.vertices[f[1]].y()
                  << ") cross: an outline's loops must not cross themselves or each other";
                throw InputError(s.str());
            }
        }
    }
}

std::vector<Vec3d> circle_points(double radius, int segments) {
    std::vector<Vec3d> loop;
    for (int k = 0; k < segments; ++k) {
        const double a = 2 * M_PI * k / segments;
        loop.emplace_back(radius * std::cos(a), radius * std::sin(a), 0);
    }
    return loop;
}

int as_count(const std::string& kind, const std::string& key, double v) {
    if (!(v == std::floor(v)) || v < 3 || v > 1e6) throw InputError(kind + ": parameter '" + key + "' must be an integer of at least 3");
    return static_cast<int>(v);
}

void require_positive(const std::string& kind, const std::map<std::string, double>& p, const char* key) {
    if (!(p.at(key) > 0)) throw InputError(kind + ": parameter '" + std::string(key) + "' must be positive");
}

const std::map<std::string, std::map<std::string, double>>& outline_defaults() {
    static const std::map<std::string, std::map<std::string, double>> d = {
        {"rectangle", {{"x", 1}, {"y", 1}}},
        {"hollow_rectangle", {{"x", 1}, {"y", 1}, {"wall", 0.1}, {"open_top", 0}}},
        {"circle", {{"radius", 0.5}, {"segments", 64}}},
        {"ring", {{"radius", 0.5}, {"wall", 0.1}, {"segments", 64}}},
    };
    return d;
}

}  // namespace

bool is_outline(const std::vector<std::array<int, 3>>& triangles) {
    return !triangles.empty() && std::all_of(triangles.begin(), triangles.end(), is_outline_edge);
}

std::vector<std::array<int, 2>> outline_edges(const TriangleMesh& outline) {
    std::vector<std::array<int, 2>> edges;
    edges.reserve(outline.triangles.size());
    for (const auto& t : outline.triangles) edges.push_back({t[0], t[1] != t[0] ? t[1] : t[2]});
    return edges;
}

TriangleMesh make_outline(const std::vector<std::vector<Vec3d>>& loops, const std::string& source) {
    TriangleMesh m;
    m.source = source;
    if (loops.empty()) throw InputError(source + ": the outline holds no loop");
    std::size_t flat_loop = 0;  // the first loop without area, reported after the crossings
    for (std::size_t l = 0; l < loops.size(); ++l) {
        const std::vector<Vec3d>& loop = loops[l];
        const int first = int(m.vertices.size());
        for (const Vec3d& p : loop) {
            if (!std::isfinite(p.x()) || !std::isfinite(p.y()))
                throw InputError(source + ": loop " + std::to_string(l + 1) + " has a non-finite point");
            m.vertices.emplace_back(p.x(), p.y(), 0.0);
        }
        if (loop.size() < 3)
            throw InputError(source + ": loop " + std::to_string(l + 1) + " has " + std::to_string(loop.size()) +
                             " point(s); a loop needs at least 3");
        const int n = int(loop.size());
        double twice_area = 0, size = 0;
        for (int k = 0; k < n; ++k) {
            const int a = first + k, b = first + (k + 1) % n, c = first + (k + 2) % n;
            if ((m.vertices[a] - m.vertices[b]).norm() == 0)
                throw InputError(source + ": loop " + std::to_string(l + 1) + " repeats point " + std::to_string(k + 1) +
                                 " (a zero-length edge; a loop closes by itself, do not repeat its first point)");
            // Two edges meeting at b that fold back onto each other touch along their length,
            // which the crossing check (edges sharing a corner are not compared) cannot see.
            const Vec3d in = m.vertices[b] - m.vertices[a], out = m.vertices[c] - m.vertices[b];
            if (cross2(in, out) == 0 && in.dot(out) < 0)
                throw InputError(source + ": loop " + std::to_string(l + 1) + " folds back on itself at point " +
                                 std::to_string((k + 1) % n + 1));
            twice_area += cross2(m.vertices[a], m.vertices[b]);
            size = std::max(size, in.norm());
            m.triangles.push_back({a, b, a});
        }
        if (!(std::fabs(twice_area) > 1e-12 * size * size) && flat_loop == 0) flat_loop = l + 1;
    }
    check_simple(m, outline_edges(m));
    if (flat_loop > 0) throw InputError(source + ": loop " + std::to_string(flat_loop) + " encloses no area");
    if (!(outline_area(m) > 0)) throw InputError(source + ": the outline encloses no area");
    return m;
}

TriangleMesh make_outline_procedural(const std::string& kind, const std::map<std::string, double>& given) {
    const auto& all = outline_defaults();
    const auto it = all.find(kind);
    if (it == all.end()) {
        std::string names;
        for (const auto& kv : all) names += (names.empty() ? "" : ", ") + kv.first;
        throw InputError("unknown procedural outline '" + kind + "' (2D scenes know: " + names + ", and line for a rod)");
    }
    const std::map<std::string, double> p = procedural_parameters(kind, it->second, given);
    const std::string source = procedural_source(kind, given);
    std::vector<std::vector<Vec3d>> loops;
    if (kind == "rectangle" || kind == "hollow_rectangle") {
        require_positive(kind, p, "x");
        require_positive(kind, p, "y");
        const double hx = p.at("x") / 2, hy = p.at("y") / 2;
        if (kind == "rectangle") {
            loops.push_back({{-hx, -hy, 0}, {hx, -hy, 0}, {hx, hy, 0}, {-hx, hy, 0}});
        } else {
            const double w = p.at("wall");
            if (!(w > 0) || !(2 * w < std::min(p.at("x"), p.at("y"))))
                throw InputError(kind + ": wall must be positive and less than half the smaller side");
            if (p.at("open_top") != 0) {
                loops.push_back({{-hx, -hy, 0}, {hx, -hy, 0}, {hx, hy, 0}, {hx - w, hy, 0}, {hx - w, -hy + w, 0},
                                 {-hx + w, -hy + w, 0}, {-hx + w, hy, 0}, {-hx, hy, 0}});
            } else {
                loops.push_back({{-hx, -hy, 0}, {hx, -hy, 0}, {hx, hy, 0}, {-hx, hy, 0}});
                loops.push_back({{-hx + w, -hy + w, 0}, {-hx + w, hy - w, 0}, {hx - w, hy - w, 0}, {hx - w, -hy + w, 0}});
            }
        }
    } else {
        require_positive(kind, p, "radius");
        const int segments = as_count(kind, "segments", p.at("segments"));
        loops.push_back(circle_points(p.at("radius"), segments));
        if (kind == "ring") {
            const double w = p.at("wall");
            if (!(w > 0) || !(w < p.at("radius"))) throw InputError(kind + ": wall must be positive and less than the radius");
            std::vector<Vec3d> inner = circle_points(p.at("radius") - w, segments);
            std::reverse(inner.begin(), inner.end());
            loops.push_back(inner);
        }
    }
    return make_outline(loops, source);
}

bool is_outline_spec(const std::string& spec) { return outline_defaults().count(spec.substr(0, spec.find(':'))) > 0; }

TriangleMesh make_outline_from_spec(const std::string& spec) {
    const ProceduralSpec parsed = parse_procedural_spec(spec);
    return make_outline_procedural(parsed.kind, parsed.params);
}

TriangleMesh load_outline(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError(path + ": cannot open the outline file");
    std::vector<std::vector<Vec3d>> loops(1);
    std::string line;
    for (int number = 1; std::getline(in, line); ++number) {
        const std::size_t hash = line.find('#');
        if (hash != std::string::npos) line.erase(hash);
        std::istringstream fields(line);
        std::string x_text, y_text, extra;
        if (!(fields >> x_text)) {
            if (!loops.back().empty()) loops.emplace_back();
            continue;
        }
        char* end_x = nullptr;
        char* end_y = nullptr;
        const double x = std::strtod(x_text.c_str(), &end_x);
        const double y = (fields >> y_text) ? std::strtod(y_text.c_str(), &end_y) : 0.0;
        if (y_text.empty() || *end_x != '\0' || *end_y != '\0' || (fields >> extra) || !std::isfinite(x) || !std::isfinite(y))
            throw InputError(path + ":" + std::to_string(number) + ": expected a point \"x y\" (two finite numbers), got \"" +
                             line + "\"");
        loops.back().emplace_back(x, y, 0.0);
    }
    if (loops.back().empty()) loops.pop_back();
    return make_outline(loops, path);
}

bool inside_loops(const std::vector<Vec3d>& points, const std::vector<std::array<int, 2>>& edges, double x, double y) {
    bool inside = false;
    for (const auto& e : edges) {
        const Vec3d& a = points[std::size_t(e[0])];
        const Vec3d& b = points[std::size_t(e[1])];
        if ((a.y() > y) != (b.y() > y) && x < a.x() + (y - a.y()) * (b.x() - a.x()) / (b.y() - a.y())) inside = !inside;
    }
    return inside;
}

std::vector<std::array<int, 2>> oriented_outline_edges(const TriangleMesh& m) {
    std::vector<std::array<int, 2>> edges = outline_edges(m);
    std::vector<std::array<int, 2>> oriented = edges;
    for (std::array<int, 2>& e : oriented) {
        const Vec3d& a = m.vertices[std::size_t(e[0])];
        const Vec3d& b = m.vertices[std::size_t(e[1])];
        const Vec3d mid = 0.5 * (a + b), left = 1e-7 * Vec3d(a.y() - b.y(), b.x() - a.x(), 0);
        if (!inside_outline(m, edges, mid.x() + left.x(), mid.y() + left.y())) std::swap(e[0], e[1]);
    }
    return oriented;
}

double outline_perimeter(const TriangleMesh& m) {
    double length = 0;
    for (const auto& e : outline_edges(m)) length += (m.vertices[std::size_t(e[1])] - m.vertices[std::size_t(e[0])]).norm();
    return length;
}

double twice_signed_area(const std::vector<Vec3d>& points, const std::vector<std::array<int, 2>>& edges) {
    double twice = 0;
    for (const auto& e : edges) twice += cross2(points[std::size_t(e[0])], points[std::size_t(e[1])]);
    return twice;
}

double outline_area(const TriangleMesh& m) {
    // Over edges with the solid on their left, holes' edges run the other way and subtract.
    return 0.5 * twice_signed_area(m.vertices, oriented_outline_edges(m));
}

}  // namespace mw
