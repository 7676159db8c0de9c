#include "sampling/procedural_meshes.hpp"

#include <cmath>
#include <cstdlib>
#include <set>
#include <sstream>
#include <unordered_map>

#include "common/errors.hpp"

namespace mw {

namespace {

struct Builder {
    TriangleMesh mesh;
    int vertex(const Vec3d& p) {
        mesh.vertices.push_back(p);
        return static_cast<int>(mesh.vertices.size()) - 1;
    }
    void tri(int a, int b, int c) { mesh.triangles.push_back({a, b, c}); }
    // Quad a b c d, counter-clockwise seen from the side it faces.
    void quad(int a, int b, int c, int d) {
        tri(a, b, c);
        tri(a, c, d);
    }
};

void require(bool ok, const std::string& what, const std::string& problem) {
    if (!ok) throw InputError(what + ": " + problem);
}

// Adds an axis-aligned box [lo, hi] facing outward (inward when `inward`).
void add_box(Builder& b, const Vec3d& lo, const Vec3d& hi, bool inward) {
    int v[8];
    for (int i = 0; i < 8; ++i) v[i] = b.vertex(Vec3d(i & 1 ? hi.x() : lo.x(), i & 2 ? hi.y() : lo.y(), i & 4 ? hi.z() : lo.z()));
    const int faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    for (const auto& f : faces) {
        if (inward)
            b.quad(v[f[0]], v[f[3]], v[f[2]], v[f[1]]);
        else
            b.quad(v[f[0]], v[f[1]], v[f[2]], v[f[3]]);
    }
}

}  // namespace

TriangleMesh make_box(const Vec3d& size) {
    require(size.allFinite() && size.minCoeff() > 0, "box", "sizes must be positive");
    Builder b;
    add_box(b, -0.5 * size, 0.5 * size, false);
    b.mesh.source = "box";
    return b.mesh;
}

TriangleMesh make_hollow_box(const Vec3d& size, double wall, bool open_top) {
    require(size.allFinite() && size.minCoeff() > 0, "hollow_box", "sizes must be positive");
    require(std::isfinite(wall) && wall > 0 && 2 * wall < size.minCoeff(), "hollow_box",
            "wall thickness must be positive and less than half the smallest size");
    Builder b;
    const Vec3d lo = -0.5 * size, hi = 0.5 * size;
    const Vec3d w(wall, wall, wall);
    if (!open_top) {
        add_box(b, lo, hi, false);
        add_box(b, lo + w, hi - w, true);
    } else {
        // One closed surface: outer bottom and sides, a rim at the top, inner sides and floor.
        const double y0 = lo.y(), y1 = hi.y(), yi = lo.y() + wall;
        const double ox[2] = {lo.x(), hi.x()}, oz[2] = {lo.z(), hi.z()};
        const double ix[2] = {lo.x() + wall, hi.x() - wall}, iz[2] = {lo.z() + wall, hi.z() - wall};
        // Corners counter-clockwise seen from +y: (x0,z1) (x1,z1) (x1,z0) (x0,z0).
        const int cx[4] = {0, 1, 1, 0}, cz[4] = {1, 1, 0, 0};
        int ob[4], ot[4], it[4], ib[4];
        for (int k = 0; k < 4; ++k) {
            ob[k] = b.vertex(Vec3d(ox[cx[k]], y0, oz[cz[k]]));
            ot[k] = b.vertex(Vec3d(ox[cx[k]], y1, oz[cz[k]]));
            it[k] = b.vertex(Vec3d(ix[cx[k]], y1, iz[cz[k]]));
            ib[k] = b.vertex(Vec3d(ix[cx[k]], yi, iz[cz[k]]));
        }
        b.quad(ob[0], ob[3], ob[2], ob[1]);  // outer bottom, facing -y
        b.quad(ib[0], ib[1], ib[2], ib[3]);  // inner floor, facing +y
        for (int k = 0; k < 4; ++k) {
            const int n = (k + 1) % 4;
            b.quad(ot[n], ot[k], ob[k], ob[n]);  // outer side, facing out
            b.quad(it[n], it[k], ot[k], ot[n]);  // rim, facing +y
            b.quad(ib[n], ib[k], it[k], it[n]);  // inner side, facing the cavity
        }
    }
    b.mesh.source = "hollow_box";
    return b.mesh;
}

TriangleMesh make_sphere(double radius, int subdivisions) {
    require(std::isfinite(radius) && radius > 0, "sphere", "radius must be positive");
    require(subdivisions >= 0 && subdivisions <= 8, "sphere", "subdivisions must be in 0..8");
    const double t = (1.0 + std::sqrt(5.0)) / 2.0;
    std::vector<Vec3d> v = {{-1, t, 0}, {1, t, 0}, {-1, -t, 0}, {1, -t, 0}, {0, -1, t}, {0, 1, t},
                            {0, -1, -t}, {0, 1, -t}, {t, 0, -1}, {t, 0, 1}, {-t, 0, -1}, {-t, 0, 1}};
    std::vector<std::array<int, 3>> f = {{0, 11, 5}, {0, 5, 1}, {0, 1, 7}, {0, 7, 10}, {0, 10, 11}, {1, 5, 9}, {5, 11, 4},
                                         {11, 10, 2}, {10, 7, 6}, {7, 1, 8}, {3, 9, 4}, {3, 4, 2}, {3, 2, 6}, {3, 6, 8},
                                         {3, 8, 9}, {4, 9, 5}, {2, 4, 11}, {6, 2, 10}, {8, 6, 7}, {9, 8, 1}};
    for (Vec3d& p : v) p.normalize();
    for (int s = 0; s < subdivisions; ++s) {
        std::unordered_map<long long, int> mid;
        auto midpoint = [&](int a, int b) {
            const long long key = a < b ? (static_cast<long long>(a) << 32) | b : (static_cast<long long>(b) << 32) | a;
            auto it = mid.find(key);
            if (it != mid.end()) return it->second;
            v.push_back((v[a] + v[b]).normalized());
            const int id = static_cast<int>(v.size()) - 1;
            mid.emplace(key, id);
            return id;
        };
        std::vector<std::array<int, 3>> g;
        g.reserve(f.size() * 4);
        for (const auto& tri : f) {
            const int a = midpoint(tri[0], tri[1]), b = midpoint(tri[1], tri[2]), c = midpoint(tri[2], tri[0]);
            g.push_back({tri[0], a, c});
            g.push_back({tri[1], b, a});
            g.push_back({tri[2], c, b});
            g.push_back({a, b, c});
        }
        f.swap(g);
    }
    TriangleMesh m;
    for (Vec3d& p : v) p *= radius;
    m.vertices = std::move(v);
    m.triangles = std::move(f);
    m.source = "sphere";
    return m;
}

TriangleMesh make_torus(double major_radius, double minor_radius, int major_segments, int minor_segments) {
    require(std::isfinite(major_radius) && std::isfinite(minor_radius) && minor_radius > 0 && major_radius > minor_radius,
            "torus", "need major > minor > 0");
    require(major_segments >= 3 && minor_segments >= 3, "torus", "need at least 3 segments each way");
    Builder b;
    const int nu = major_segments, nv = minor_segments;
    for (int i = 0; i < nu; ++i) {
        const double u = 2 * M_PI * i / nu;
        for (int j = 0; j < nv; ++j) {
            const double w = 2 * M_PI * j / nv;
            const double r = major_radius + minor_radius * std::cos(w);
            b.vertex(Vec3d(r * std::cos(u), minor_radius * std::sin(w), -r * std::sin(u)));
        }
    }
    auto id = [&](int i, int j) { return ((i % nu) * nv) + (j % nv); };
    for (int i = 0; i < nu; ++i)
        for (int j = 0; j < nv; ++j) b.quad(id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
    b.mesh.source = "torus";
    return b.mesh;
}

TriangleMesh make_cylinder(double radius, double height, int segments) {
    require(std::isfinite(radius) && radius > 0 && std::isfinite(height) && height > 0, "cylinder",
            "radius and height must be positive");
    require(segments >= 3, "cylinder", "need at least 3 segments");
    Builder b;
    const int n = segments;
    const int bottom = b.vertex(Vec3d(0, -0.5 * height, 0)), top = b.vertex(Vec3d(0, 0.5 * height, 0));
    for (int i = 0; i < n; ++i) {
        const double u = 2 * M_PI * i / n;
        b.vertex(Vec3d(radius * std::cos(u), -0.5 * height, -radius * std::sin(u)));
        b.vertex(Vec3d(radius * std::cos(u), 0.5 * height, -radius * std::sin(u)));
    }
    auto lo = [&](int i) { return 2 + 2 * (i % n); };
    auto hi = [&](int i) { return 3 + 2 * (i % n); };
    for (int i = 0; i < n; ++i) {
        b.quad(lo(i), lo(i + 1), hi(i + 1), hi(i));
        b.tri(top, hi(i), hi(i + 1));
        b.tri(bottom, lo(i + 1), lo(i));
    }
    b.mesh.source = "cylinder";
    return b.mesh;
}

TriangleMesh make_stairs(int steps, double width, double depth, double height) {
    require(steps >= 1 && steps <= 10000, "stairs", "steps must be in 1..10000");
    require(std::isfinite(width) && width > 0 && std::isfinite(depth) && depth > 0 && std::isfinite(height) && height > 0,
            "stairs", "width, depth and height must be positive");
    Builder b;
    const int n = steps;
    const double x[2] = {-0.5 * width, 0.5 * width};
    const Vec3d shift(0, -0.5 * n * height, -0.5 * n * depth);  // centre the bounding box
    // Profile points in (z, y): bottom row B_k = (k d, 0), k = 0..n; step corners
    // L_k = (k d, k h) (inner corner, k = 1..n-1 only matters) and U_k = (k d, (k+1) h), k = 0..n-1;
    // back top T = (n d, n h).
    auto add = [&](double z, double y, int side) { return b.vertex(Vec3d(x[side], y, z) + shift); };
    std::vector<int> B[2], L[2], U[2], T(2);
    for (int s = 0; s < 2; ++s) {
        for (int k = 0; k <= n; ++k) B[s].push_back(add(k * depth, 0, s));
        for (int k = 0; k < n; ++k) L[s].push_back(k == 0 ? B[s][0] : add(k * depth, k * height, s));
        for (int k = 0; k < n; ++k) U[s].push_back(add(k * depth, (k + 1) * height, s));
        T[s] = add(n * depth, n * height, s);
    }
    for (int k = 0; k < n; ++k) {
        // Side faces (x = -w/2 faces -x, x = +w/2 faces +x). Column k polygon in (z, y):
        // B_k, B_{k+1}, ur = ((k+1) d, (k+1) h), U_k, and L_k on its left edge when k > 0 (so
        // that the sides share every vertex with the risers: no T-junctions). Fan from B_{k+1}.
        for (int s = 0; s < 2; ++s) {
            const int ur = (k + 1 < n) ? L[s][k + 1] : T[s];
            const int poly[5] = {B[s][k], B[s][k + 1], ur, U[s][k], L[s][k]};
            const int count = (k == 0) ? 4 : 5;
            for (int i = 2; i < count; ++i) {
                const int a = poly[1], p = poly[i], q = poly[(i + 1) % count];
                if (s == 0) b.tri(a, p, q); else b.tri(a, q, p);
            }
        }
        // Tread of step k at y = (k+1) h, z in [k d, (k+1) d], facing +y.
        const int f0 = U[0][k], f1 = U[1][k];
        const int r0 = (k + 1 < n) ? L[0][k + 1] : T[0], r1 = (k + 1 < n) ? L[1][k + 1] : T[1];
        b.quad(f0, r0, r1, f1);
        // Riser of step k at z = k d, y in [k h, (k+1) h], facing -z.
        b.quad(L[0][k], U[0][k], U[1][k], L[1][k]);
        // Bottom strip k at y = 0, facing -y.
        b.quad(B[0][k], B[1][k], B[1][k + 1], B[0][k + 1]);
    }
    // Back face at z = n d, facing +z.
    b.quad(B[0][n], B[1][n], T[1], T[0]);
    b.mesh.source = "stairs";
    return b.mesh;
}

TriangleMesh make_line(double length) {
    require(std::isfinite(length) && length > 0, "line", "length must be positive");
    TriangleMesh m;
    m.vertices = {Vec3d(-length / 2, 0, 0), Vec3d(length / 2, 0, 0)};
    m.source = "line";
    return m;
}

TriangleMesh make_sheet(double size_x, double size_z, int nx, int nz) {
    require(std::isfinite(size_x) && size_x > 0 && std::isfinite(size_z) && size_z > 0, "sheet", "sizes must be positive");
    require(nx >= 1 && nz >= 1, "sheet", "need at least one quad each way");
    Builder b;
    for (int j = 0; j <= nz; ++j)
        for (int i = 0; i <= nx; ++i) b.vertex(Vec3d(size_x * (double(i) / nx - 0.5), 0, size_z * (double(j) / nz - 0.5)));
    auto id = [&](int i, int j) { return j * (nx + 1) + i; };
    for (int j = 0; j < nz; ++j)
        for (int i = 0; i < nx; ++i) b.quad(id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j));
    b.mesh.source = "sheet";
    return b.mesh;
}

namespace {

const std::map<std::string, std::map<std::string, double>>& procedural_defaults() {
    static const std::map<std::string, std::map<std::string, double>> d = {
        {"box", {{"x", 1}, {"y", 1}, {"z", 1}}},
        {"hollow_box", {{"x", 1}, {"y", 1}, {"z", 1}, {"wall", 0.1}, {"open_top", 0}}},
        {"sphere", {{"radius", 0.5}, {"subdivisions", 4}}},
        {"torus", {{"major", 0.35}, {"minor", 0.15}, {"major_segments", 48}, {"minor_segments", 24}}},
        {"cylinder", {{"radius", 0.5}, {"height", 1}, {"segments", 48}}},
        {"stairs", {{"steps", 5}, {"width", 1}, {"depth", 0.2}, {"height", 0.1}}},
        {"sheet", {{"x", 1}, {"z", 1}, {"nx", 16}, {"nz", 16}}},
        {"line", {{"length", 1}}},
    };
    return d;
}

int as_int(const std::string& kind, const std::string& key, double v) {
    if (!(v == std::floor(v)) || std::abs(v) > 1e6) throw InputError(kind + ": parameter '" + key + "' must be an integer");
    return static_cast<int>(v);
}

}  // namespace

bool is_procedural_spec(const std::string& spec) {
    const std::string kind = spec.substr(0, spec.find(':'));
    return procedural_defaults().count(kind) > 0;
}

TriangleMesh make_procedural(const std::string& kind, const std::map<std::string, double>& params) {
    const auto& all = procedural_defaults();
    auto it = all.find(kind);
    if (it == all.end()) {
        std::string names;
        for (const auto& kv : all) names += (names.empty() ? "" : ", ") + kv.first;
        throw InputError("unknown procedural mesh '" + kind + "' (known: " + names + ")");
    }
    std::map<std::string, double> p = procedural_parameters(kind, it->second, params);
    TriangleMesh m;
    if (kind == "box") m = make_box(Vec3d(p["x"], p["y"], p["z"]));
    else if (kind == "hollow_box") m = make_hollow_box(Vec3d(p["x"], p["y"], p["z"]), p["wall"], p["open_top"] != 0);
    else if (kind == "sphere") m = make_sphere(p["radius"], as_int(kind, "subdivisions", p["subdivisions"]));
    else if (kind == "torus")
        m = make_torus(p["major"], p["minor"], as_int(kind, "major_segments", p["major_segments"]),
                       as_int(kind, "minor_segments", p["minor_segments"]));
    else if (kind == "cylinder") m = make_cylinder(p["radius"], p["height"], as_int(kind, "segments", p["segments"]));
    else if (kind == "stairs") m = make_stairs(as_int(kind, "steps", p["steps"]), p["width"], p["depth"], p["height"]);
    else if (kind == "sheet") m = make_sheet(p["x"], p["z"], as_int(kind, "nx", p["nx"]), as_int(kind, "nz", p["nz"]));
    else m = make_line(p["length"]);
    m.source = procedural_source(kind, params);
    return m;
}

ProceduralSpec parse_procedural_spec(const std::string& spec) {
    const std::size_t colon = spec.find(':');
    ProceduralSpec out;
    out.kind = spec.substr(0, colon);
    if (colon == std::string::npos) return out;
    std::stringstream rest(spec.substr(colon + 1));
    std::string item;
    while (std::getline(rest, item, ',')) {
        if (item.empty()) continue;
        const std::size_t eq = item.find('=');
        if (eq == std::string::npos) throw InputError(spec + ": expected key=value, got '" + item + "'");
        const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
        char* end = nullptr;
        const double v = std::strtod(value.c_str(), &end);
        if (value.empty() || end == nullptr || *end != '\0')
            throw InputError(spec + ": parameter '" + key + "' is not a number ('" + value + "')");
        out.params[key] = v;
    }
    return out;
}

std::map<std::string, double> procedural_parameters(const std::string& kind, const std::map<std::string, double>& defaults,
                                                    const std::map<std::string, double>& given) {
    std::map<std::string, double> p = defaults;
    for (const auto& kv : given) {
        if (!p.count(kv.first)) {
            std::string names;
            for (const auto& d : defaults) names += (names.empty() ? "" : ", ") + d.first;
            throw InputError(kind + ": unknown parameter '" + kv.first + "' (known: " + names + ")");
        }
        if (!std::isfinite(kv.second)) throw InputError(kind + ": parameter '" + kv.first + "' is not finite");
        p[kv.first] = kv.second;
    }
    return p;
}

std::string procedural_source(const std::string& kind, const std::map<std::string, double>& given) {
    std::ostringstream src;
    src << kind;
    for (const auto& kv : given) src << (kv.first == given.begin()->first ? ":" : ",") << kv.first << "=" << kv.second;
    return src.str();
}

TriangleMesh make_procedural_from_spec(const std::string& spec) {
    const ProceduralSpec parsed = parse_procedural_spec(spec);
    return make_procedural(parsed.kind, parsed.params);
}

}  // namespace mw
