#include "render/preview.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <stdexcept>

namespace mw {

namespace {

constexpr double kPi = 3.14159265358979323846;

// ---- Vectors and the camera's frame ------------------------------------------------------------

struct D3 {
    double x = 0, y = 0, z = 0;
};
D3 operator+(D3 a, D3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
D3 operator-(D3 a, D3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
D3 operator*(double s, D3 a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(D3 a, D3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
D3 cross(D3 a, D3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
double norm(D3 a) { return std::sqrt(dot(a, a)); }
D3 normalized(D3 a) {
    const double n = norm(a);
    return n > 0 ? (1.0 / n) * a : D3{};
}
D3 d3(const PreviewVec& v) { return {v[0], v[1], v[2]}; }
D3 vertex(const std::vector<float>& xyz, std::size_t i) {
    return {double(xyz[3 * i]), double(xyz[3 * i + 1]), double(xyz[3 * i + 2])};
}

// The light, in the camera's frame (x right, y up, z toward the viewer): from the upper left, over
// the viewer's shoulder, the way a figure in a paper is usually lit; fixed to the camera, so every
// view is lit the same and no side the viewer sees is left in the dark.
const D3 kLight = normalized({-0.45, 0.65, 0.62});

// The colour under a light of strength `shade` (clamped to [0, 1]): shaded() with float rounding,
// as this runs once per pixel written and shaded()'s double lround is most of a splat's cost.
inline Rgb lit(Rgb c, float shade) {
    const float s = std::clamp(shade, 0.0f, 1.0f);
    return {std::uint8_t(float(c.r) * s + 0.5f), std::uint8_t(float(c.g) * s + 0.5f), std::uint8_t(float(c.b) * s + 0.5f)};
}

// Where the camera is and how it maps a point to a pixel. Camera coordinates: x to the right, y up,
// z the depth in front of the eye (positive is visible).
struct Projector {
    D3 eye, right, up, forward;
    double focal = 1;   // pixels per unit of x / z
    double cx = 0, cy = 0;
    double near = 0;    // nothing nearer than this depth is drawn

    D3 to_camera(D3 p) const {
        const D3 d = p - eye;
        return {dot(d, right), dot(d, up), dot(d, forward)};
    }
    // A world direction (a normal) in the lighting frame, z toward the viewer.
    D3 to_light_frame(D3 n) const { return {dot(n, right), dot(n, up), -dot(n, forward)}; }
    double screen_x(D3 c) const { return cx + focal * c.x / c.z; }
    double screen_y(D3 c) const { return cy - focal * c.y / c.z; }
};

Projector make_projector(const PreviewCamera& camera, int width, int height) {
    const D3 eye = d3(camera.eye), target = d3(camera.target);
    const double distance = norm(target - eye);
    if (!(distance > 0) || !std::isfinite(distance))
        throw std::invalid_argument("preview camera: the eye and the target must be distinct finite points");
    if (!(camera.fov_y_degrees > 0.5 && camera.fov_y_degrees < 170))
        throw std::invalid_argument("preview camera: the field of view must lie between 0.5 and 170 degrees");
    Projector p;
    p.eye = eye;
    p.forward = (1.0 / distance) * (target - eye);
    D3 up = d3(camera.up);
    // An up along the line of sight leaves the roll undefined; any perpendicular will do then.
    if (norm(cross(p.forward, up)) < 1e-9 * std::max(norm(up), 1e-300))
        up = std::fabs(p.forward.y) < 0.9 ? D3{0, 1, 0} : D3{1, 0, 0};
    p.right = normalized(cross(p.forward, up));
    p.up = cross(p.right, p.forward);
    p.focal = 0.5 * height / std::tan(0.5 * camera.fov_y_degrees * kPi / 180.0);
    p.cx = 0.5 * width;
    p.cy = 0.5 * height;
    p.near = 1e-4 * distance;
    return p;
}

// ---- Buffers and bands of rows -----------------------------------------------------------------

// The picture being drawn, at the supersampled size: a colour and a depth (camera z of the nearest
// surface so far) per pixel.
struct Canvas {
    int width, height;
    std::vector<Rgb> colour;
    std::vector<float> depth;
    std::size_t at(int x, int y) const { return std::size_t(y) * std::size_t(width) + std::size_t(x); }
};

// Rows are drawn in bands, one thread per band at a time, so no two threads touch a pixel and each
// band draws its primitives in input order: the result does not depend on the thread count.
constexpr int kBandRows = 16;

// For each band, the primitives whose rows [first, last] reach into it, in input order (CSR).
struct Bins {
    std::vector<std::size_t> start;
    std::vector<std::uint32_t> items;
};

template <class Primitive>
Bins bin_by_band(const std::vector<Primitive>& primitives, int height) {
    const int bands = (height + kBandRows - 1) / kBandRows;
    Bins bins;
    bins.start.assign(std::size_t(bands) + 1, 0);
    for (const Primitive& p : primitives)
        if (p.y0 <= p.y1)
            for (int b = p.y0 / kBandRows; b <= p.y1 / kBandRows; ++b) ++bins.start[std::size_t(b) + 1];
    for (int b = 0; b < bands; ++b) bins.start[std::size_t(b) + 1] += bins.start[std::size_t(b)];
    bins.items.resize(bins.start.back());
    std::vector<std::size_t> fill(bins.start.begin(), bins.start.end() - 1);
    for (std::size_t i = 0; i < primitives.size(); ++i) {
        const Primitive& p = primitives[i];
        if (p.y0 <= p.y1)
            for (int b = p.y0 / kBandRows; b <= p.y1 / kBandRows; ++b)
                bins.items[fill[std::size_t(b)]++] = std::uint32_t(i);
    }
    return bins;
}

// Calls draw(primitive, band's first row, band's last row) for each band's primitives, bands in
// parallel.
template <class Primitive, class Draw>
void draw_in_bands(const std::vector<Primitive>& primitives, int height, Draw draw) {
    const Bins bins = bin_by_band(primitives, height);
    const int bands = int(bins.start.size()) - 1;
#pragma omp parallel for schedule(dynamic, 1)
    for (int b = 0; b < bands; ++b) {
        const int row0 = b * kBandRows, row1 = std::min(height, row0 + kBandRows) - 1;
        for (std::size_t k = bins.start[std::size_t(b)]; k < bins.start[std::size_t(b) + 1]; ++k)
            draw(primitives[bins.items[k]], row0, row1);
    }
}

int clamp_row(double y, int height) { return int(std::clamp(y, -1.0, double(height))); }

// ---- Particles as sphere splats ----------------------------------------------------------------

struct Splat {
    float sx, sy;       // centre on the screen, pixels
    float radius_px;    // the disc's radius on the screen
    float depth;        // camera z of the sphere's centre
    float radius;       // the sphere's radius, world units (the bulge toward the viewer)
    Rgb colour;
    int y0, y1;         // rows covered; y0 > y1 when nothing is drawn
};

Rgb particle_colour(const PreviewFrame& frame, const PreviewStyle& style, std::size_t i, double lo, double span) {
    switch (frame.kinds[i]) {
        case PreviewKind::fluid:
            return frame.values.empty() ? style.water_colour : colour_map((double(frame.values[i]) - lo) / span);
        case PreviewKind::solid: return style.solid_colour;
        default: return style.boundary_colour;
    }
}

std::vector<Splat> project_all(const PreviewFrame& frame, const PreviewStyle& style, const Projector& view,
                                     const Canvas& canvas, std::array<double, 2> range) {
    const std::size_t n = frame.kinds.size();
    const double radius = frame.particle_radius * style.splat_scale;
    const double span = range[1] - range[0];
    // A far particle still covers a pixel centre, so a distant cloud thins out instead of vanishing.
    const double min_radius_px = 0.75 * style.supersample;
    std::vector<Splat> splats(n);
#pragma omp parallel for schedule(static)
    for (long long k = 0; k < (long long)n; ++k) {
        const std::size_t i = std::size_t(k);
        Splat& s = splats[i];
        s.y0 = 1, s.y1 = 0;
        const PreviewKind kind = frame.kinds[i];
        if (kind == PreviewKind::hidden || (kind == PreviewKind::boundary && !style.show_boundary)) continue;
        const D3 c = view.to_camera(vertex(frame.positions, i));
        // Behind the eye, or so close that the sphere would wrap round it: not drawn.
        if (!(c.z > std::max(view.near, radius))) continue;
        const double sx = view.screen_x(c), sy = view.screen_y(c);
        const double r = std::max(radius * view.focal / c.z, min_radius_px);
        if (sx + r < 0 || sx - r > canvas.width || !std::isfinite(sx) || !std::isfinite(sy)) continue;
        s.sx = float(sx), s.sy = float(sy), s.radius_px = float(r);
        s.depth = float(c.z), s.radius = float(radius);
        s.colour = particle_colour(frame, style, i, range[0], span);
        s.y0 = std::max(0, clamp_row(std::floor(sy - r), canvas.height));
        s.y1 = std::min(canvas.height - 1, clamp_row(std::ceil(sy + r), canvas.height));
    }
    return splats;
}

// The visible splats, nearest first: a band then rejects most of a hidden splat's pixels at the
// depth test instead of shading them and shading them again. Ties in depth go by input order, so
// the order (and the picture) is one for any thread count.
std::vector<Splat> project_particles(const PreviewFrame& frame, const PreviewStyle& style, const Projector& view,
                                     const Canvas& canvas, std::array<double, 2> range) {
    std::vector<Splat> all = project_all(frame, style, view, canvas, range);
    std::vector<std::uint32_t> order;
    for (std::size_t i = 0; i < all.size(); ++i)
        if (all[i].y0 <= all[i].y1) order.push_back(std::uint32_t(i));
    std::sort(order.begin(), order.end(), [&all](std::uint32_t a, std::uint32_t b) {
        return all[a].depth < all[b].depth || (all[a].depth == all[b].depth && a < b);
    });
    std::vector<Splat> visible(order.size());
    for (std::size_t k = 0; k < order.size(); ++k) visible[k] = all[order[k]];
    return visible;
}

// One splat's pixels within rows [row0, row1]: the sphere's front at each pixel centre is its
// centre's depth less the bulge radius * sqrt(1 - d^2), and its normal is (u, -v, sqrt(1 - d^2)).
void draw_splat(Canvas& canvas, const Splat& s, int row0, int row1, double ambient) {
    const int y0 = std::max(s.y0, row0), y1 = std::min(s.y1, row1);
    const float inv_r = 1.0f / s.radius_px, diffuse = float(1 - ambient);
    const float lx = float(kLight.x), ly = float(kLight.y), lz = float(kLight.z);
    const float front = s.depth - s.radius;  // the sphere's nearest point: behind this, nothing shows
    for (int y = y0; y <= y1; ++y) {
        const float v = (float(y) + 0.5f - s.sy) * inv_r;
        if (v * v > 1) continue;
        // Only the row's chord of the disc.
        const float half = s.radius_px * std::sqrt(1 - v * v);
        const int x0 = std::max(0, int(std::floor(s.sx - half))), x1 = std::min(canvas.width - 1, int(s.sx + half));
        for (int x = x0; x <= x1; ++x) {
            const std::size_t p = canvas.at(x, y);
            if (!(front < canvas.depth[p])) continue;
            const float u = (float(x) + 0.5f - s.sx) * inv_r;
            const float d2 = u * u + v * v;
            if (d2 > 1) continue;
            const float h = std::sqrt(1 - d2);
            const float z = s.depth - s.radius * h;
            if (!(z < canvas.depth[p])) continue;
            canvas.depth[p] = z;
            const float lambert = std::max(0.0f, u * lx - v * ly + h * lz);
            canvas.colour[p] = lit(s.colour, float(ambient) + diffuse * lambert);
        }
    }
}

// ---- Triangles -----------------------------------------------------------------------------------

// A triangle ready to fill: screen corners, 1/depth at each (linear on the screen, so depth and
// normals interpolate with the perspective), and the corners' normals in the lighting frame.
struct ScreenTriangle {
    float x[3], y[3], inv_z[3];
    D3 normal[3];
    Rgb colour;
    float opacity;
    int y0, y1;
};

struct CameraVertex {
    D3 c;       // camera coordinates
    D3 normal;  // lighting frame
};

// A triangle cut by the near plane keeps up to four corners.
struct Polygon {
    CameraVertex corner[4];
    int size = 0;
};

// The part of a triangle in front of the near plane (Sutherland-Hodgman against one plane).
Polygon clip_near(const Polygon& in, double near) {
    Polygon out;
    for (int i = 0; i < in.size; ++i) {
        const CameraVertex& a = in.corner[i];
        const CameraVertex& b = in.corner[(i + 1) % in.size];
        const bool a_in = a.c.z >= near, b_in = b.c.z >= near;
        if (a_in) out.corner[out.size++] = a;
        if (a_in != b_in) {
            const double t = (near - a.c.z) / (b.c.z - a.c.z);
            out.corner[out.size++] = {a.c + t * (b.c - a.c), a.normal + t * (b.normal - a.normal)};
        }
    }
    return out;
}

// Appends the visible pieces of one world triangle (corners p, normals n) to `out`.
void add_triangle(std::vector<ScreenTriangle>& out, const Projector& view, const Canvas& canvas, const D3 p[3],
                  const D3 n[3], Rgb colour, float opacity) {
    // Lit from the side the viewer sees: a surface seen from behind turns its normals round.
    const D3 face = cross(p[1] - p[0], p[2] - p[0]);
    const double side = dot(face, view.eye - p[0]) < 0 ? -1.0 : 1.0;
    Polygon poly;
    poly.size = 3;
    for (int k = 0; k < 3; ++k) poly.corner[k] = {view.to_camera(p[k]), view.to_light_frame(side * n[k])};
    if (poly.corner[0].c.z < view.near || poly.corner[1].c.z < view.near || poly.corner[2].c.z < view.near)
        poly = clip_near(poly, view.near);
    for (int k = 1; k + 1 < poly.size; ++k) {
        const CameraVertex* corner[3] = {&poly.corner[0], &poly.corner[k], &poly.corner[k + 1]};
        ScreenTriangle t;
        double ymin = std::numeric_limits<double>::infinity(), ymax = -ymin, xmin = ymin, xmax = -ymin;
        for (int j = 0; j < 3; ++j) {
            const D3 c = corner[j]->c;
            const double sx = view.screen_x(c), sy = view.screen_y(c);
            t.x[j] = float(sx), t.y[j] = float(sy), t.inv_z[j] = float(1.0 / c.z);
            t.normal[j] = (1.0 / c.z) * corner[j]->normal;
            ymin = std::min(ymin, sy), ymax = std::max(ymax, sy), xmin = std::min(xmin, sx), xmax = std::max(xmax, sx);
        }
        if (xmax < 0 || xmin > canvas.width || !std::isfinite(ymin + ymax + xmin + xmax)) continue;
        t.colour = colour, t.opacity = opacity;
        t.y0 = std::max(0, clamp_row(std::floor(ymin), canvas.height));
        t.y1 = std::min(canvas.height - 1, clamp_row(std::ceil(ymax), canvas.height));
        out.push_back(t);
    }
}

// The mesh's normals at its vertices, for smooth shading: the sum of the faces' normals weighted
// by their areas (a large face outweighs a sliver), normalised.
std::vector<D3> vertex_normals(const PreviewMesh& mesh) {
    std::vector<D3> normals(mesh.vertices.size() / 3);
    for (std::size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
        const std::uint32_t* v = &mesh.triangles[t];
        const D3 face = cross(vertex(mesh.vertices, v[1]) - vertex(mesh.vertices, v[0]),
                              vertex(mesh.vertices, v[2]) - vertex(mesh.vertices, v[0]));
        for (int k = 0; k < 3; ++k) normals[v[k]] = normals[v[k]] + face;
    }
    for (D3& n : normals) n = normalized(n);
    return normals;
}

void add_mesh(std::vector<ScreenTriangle>& out, const PreviewMesh& mesh, const Projector& view, const Canvas& canvas) {
    const std::vector<D3> normals = mesh.smooth ? vertex_normals(mesh) : std::vector<D3>{};
    for (std::size_t t = 0; t + 2 < mesh.triangles.size(); t += 3) {
        D3 p[3], n[3];
        for (int k = 0; k < 3; ++k) p[k] = vertex(mesh.vertices, mesh.triangles[t + std::size_t(k)]);
        const D3 face = normalized(cross(p[1] - p[0], p[2] - p[0]));
        for (int k = 0; k < 3; ++k) {
            n[k] = mesh.smooth ? normals[mesh.triangles[t + std::size_t(k)]] : face;
            // A vertex whose faces cancel out (a fold) takes the face's own normal.
            if (norm(n[k]) == 0) n[k] = face;
        }
        add_triangle(out, view, canvas, p, n, mesh.colour, mesh.opacity);
    }
}

// Fills the triangle's pixel centres within rows [row0, row1] that pass the depth test against
// `depth`, writing colour (and, for a translucent layer, the opacity) there.
void draw_triangle(Canvas& canvas, std::vector<float>* alpha, const ScreenTriangle& t, int row0, int row1,
                   double ambient) {
    const double area = double(t.x[1] - t.x[0]) * (t.y[2] - t.y[0]) - double(t.x[2] - t.x[0]) * (t.y[1] - t.y[0]);
    if (area == 0 || !std::isfinite(area)) return;
    const double inv_area = 1.0 / area;
    const int y0 = std::max(t.y0, row0), y1 = std::min(t.y1, row1);
    const int x0 = std::max(0, int(std::floor(std::min({t.x[0], t.x[1], t.x[2]}))));
    const int x1 = std::min(canvas.width - 1, int(std::ceil(std::max({t.x[0], t.x[1], t.x[2]}))));
    for (int y = y0; y <= y1; ++y) {
        const double py = y + 0.5;
        for (int x = x0; x <= x1; ++x) {
            const double px = x + 0.5;
            // Barycentric weights from the edge functions, positive inside whatever the winding.
            const double w0 = ((t.x[1] - px) * (t.y[2] - py) - (t.x[2] - px) * (t.y[1] - py)) * inv_area;
            const double w1 = ((t.x[2] - px) * (t.y[0] - py) - (t.x[0] - px) * (t.y[2] - py)) * inv_area;
            const double w2 = 1 - w0 - w1;
            if (w0 < 0 || w1 < 0 || w2 < 0) continue;
            const double inv_z = w0 * t.inv_z[0] + w1 * t.inv_z[1] + w2 * t.inv_z[2];
            const float z = float(1.0 / inv_z);
            const std::size_t p = canvas.at(x, y);
            if (!(z < canvas.depth[p])) continue;
            canvas.depth[p] = z;
            const D3 n = normalized(w0 * t.normal[0] + w1 * t.normal[1] + w2 * t.normal[2]);
            canvas.colour[p] = lit(t.colour, float(ambient + (1 - ambient) * std::max(0.0, dot(n, kLight))));
            if (alpha) (*alpha)[p] = t.opacity;
        }
    }
}

void draw_opaque(Canvas& canvas, const std::vector<ScreenTriangle>& triangles, double ambient) {
    draw_in_bands(triangles, canvas.height,
                  [&](const ScreenTriangle& t, int r0, int r1) { draw_triangle(canvas, nullptr, t, r0, r1, ambient); });
}

// The translucent triangles go into a layer of their own that starts from the canvas's depths (so
// what is hidden stays hidden); only the nearest translucent surface at a pixel is blended over
// the canvas, which needs no sorting and is the same whatever the triangles' order.
void draw_translucent(Canvas& canvas, const std::vector<ScreenTriangle>& triangles, double ambient) {
    if (triangles.empty()) return;
    Canvas layer{canvas.width, canvas.height, canvas.colour, canvas.depth};
    std::vector<float> alpha(canvas.colour.size(), 0.0f);
    draw_in_bands(triangles, canvas.height,
                  [&](const ScreenTriangle& t, int r0, int r1) { draw_triangle(layer, &alpha, t, r0, r1, ambient); });
#pragma omp parallel for schedule(static)
    for (long long k = 0; k < (long long)alpha.size(); ++k) {
        const std::size_t p = std::size_t(k);
        const float a = std::clamp(alpha[p], 0.0f, 1.0f);
        if (a <= 0) continue;
        const Rgb under = canvas.colour[p], over = layer.colour[p];
        const auto mix = [a](std::uint8_t u, std::uint8_t o) {
            return std::uint8_t(std::lround(float(u) + a * (float(o) - float(u))));
        };
        canvas.colour[p] = {mix(under.r, over.r), mix(under.g, over.g), mix(under.b, over.b)};
    }
}

// ---- The domain: a floor of tiles and the box's edges ------------------------------------------

// A round tile size (1, 2 or 5 times a power of ten) giving about a dozen tiles along the floor's
// longer side: the checkerboard then doubles as a scale bar.
double tile_size(double longer_side) {
    const double rough = longer_side / 12;
    const double decade = std::pow(10.0, std::floor(std::log10(rough)));
    for (double m : {1.0, 2.0, 5.0})
        if (m * decade >= 0.75 * rough) return m * decade;
    return 10 * decade;
}

// The floor (the box's face at lo.y) as two meshes, one per colour of the checkerboard; tiles at
// the far edges are cut to the box.
std::vector<PreviewMesh> floor_meshes(const PreviewVec& lo, const PreviewVec& hi, const PreviewStyle& style) {
    std::vector<PreviewMesh> meshes(2);
    for (std::size_t c = 0; c < 2; ++c) {
        meshes[c].colour = style.floor_colours[c];
        meshes[c].smooth = false;
    }
    const double lx = hi[0] - lo[0], lz = hi[2] - lo[2];
    if (!(lx > 0) || !(lz > 0)) return {};
    const double step = tile_size(std::max(lx, lz));
    const int nx = std::min(1000, int(std::ceil(lx / step - 1e-9))), nz = std::min(1000, int(std::ceil(lz / step - 1e-9)));
    for (int i = 0; i < nx; ++i)
        for (int j = 0; j < nz; ++j) {
            PreviewMesh& m = meshes[std::size_t((i + j) % 2)];
            const auto first = std::uint32_t(m.vertices.size() / 3);
            const double x0 = lo[0] + i * step, x1 = std::min(hi[0], x0 + step);
            const double z0 = lo[2] + j * step, z1 = std::min(hi[2], z0 + step);
            for (const auto& [x, z] : {std::pair{x0, z0}, std::pair{x1, z0}, std::pair{x1, z1}, std::pair{x0, z1}})
                m.vertices.insert(m.vertices.end(), {float(x), float(lo[1]), float(z)});
            m.triangles.insert(m.triangles.end(), {first, first + 1, first + 2, first, first + 2, first + 3});
        }
    return meshes;
}

// A depth-tested line between two world points, `thickness` canvas pixels wide. It leaves the
// depths alone (a line hides nothing) and passes a little behind the nearest surface, so the
// floor's own edges show on the floor.
void draw_edge(Canvas& canvas, const Projector& view, D3 a, D3 b, Rgb colour, int thickness) {
    D3 ca = view.to_camera(a), cb = view.to_camera(b);
    if (ca.z < view.near && cb.z < view.near) return;
    if (ca.z < view.near) ca = ca + ((view.near - ca.z) / (cb.z - ca.z)) * (cb - ca);
    if (cb.z < view.near) cb = cb + ((view.near - cb.z) / (ca.z - cb.z)) * (ca - cb);
    const double x0 = view.screen_x(ca), y0 = view.screen_y(ca), x1 = view.screen_x(cb), y1 = view.screen_y(cb);
    const double iz0 = 1 / ca.z, iz1 = 1 / cb.z;
    // Only the part on the canvas is walked (Liang-Barsky on the canvas's rectangle, loosened).
    double t0 = 0, t1 = 1;
    const double dx = x1 - x0, dy = y1 - y0, pad = thickness + 1;
    const double p[4] = {-dx, dx, -dy, dy};
    const double q[4] = {x0 + pad, canvas.width + pad - x0, y0 + pad, canvas.height + pad - y0};
    for (int k = 0; k < 4; ++k) {
        if (p[k] == 0) {
            if (q[k] < 0) return;
            continue;
        }
        const double r = q[k] / p[k];
        if (p[k] < 0) t0 = std::max(t0, r);
        else t1 = std::min(t1, r);
    }
    if (t0 > t1) return;
    const int steps = int(std::ceil((t1 - t0) * std::max(std::fabs(dx), std::fabs(dy)))) + 1;
    const int lo = -(thickness - 1) / 2, hi = thickness / 2;
    for (int s = 0; s <= steps; ++s) {
        const double t = t0 + (t1 - t0) * s / steps;
        const int px = int(std::floor(x0 + t * dx)), py = int(std::floor(y0 + t * dy));
        const float z = float(1.0 / (iz0 + t * (iz1 - iz0)));
        for (int oy = lo; oy <= hi; ++oy)
            for (int ox = lo; ox <= hi; ++ox) {
                const int x = px + ox, y = py + oy;
                if (x < 0 || y < 0 || x >= canvas.width || y >= canvas.height) continue;
                const std::size_t i = canvas.at(x, y);
                if (z <= canvas.depth[i] * 1.004f) canvas.colour[i] = colour;
            }
    }
}

void draw_box_edges(Canvas& canvas, const Projector& view, const PreviewVec& lo, const PreviewVec& hi, Rgb colour,
                    int thickness) {
    const auto corner = [&](int k) { return D3{k & 1 ? hi[0] : lo[0], k & 2 ? hi[1] : lo[1], k & 4 ? hi[2] : lo[2]}; };
    // The corners k and k + bit differ along one axis: those twelve pairs are the edges.
    for (int k = 0; k < 8; ++k)
        for (int bit : {1, 2, 4})
            if (!(k & bit)) draw_edge(canvas, view, corner(k), corner(k | bit), colour, thickness);
}

// ---- The picture's frame: background, downsampling, legend, caption ----------------------------

void fill_background(Canvas& canvas, Rgb top, Rgb bottom) {
#pragma omp parallel for schedule(static)
    for (int y = 0; y < canvas.height; ++y) {
        const double f = canvas.height > 1 ? double(y) / (canvas.height - 1) : 0.0;
        const auto mix = [f](std::uint8_t a, std::uint8_t b) { return std::uint8_t(std::lround(a + f * (double(b) - a))); };
        const Rgb c{mix(top.r, bottom.r), mix(top.g, bottom.g), mix(top.b, bottom.b)};
        std::fill_n(canvas.colour.begin() + std::ptrdiff_t(canvas.at(0, y)), canvas.width, c);
    }
}

// Each pixel of the picture is the mean of its s x s canvas pixels: smooth silhouettes and edges.
Image downsample(const Canvas& canvas, int s) {
    Image image(canvas.width / s, canvas.height / s, Rgb{});
    const int n = s * s;
#pragma omp parallel for schedule(static)
    for (int y = 0; y < image.height(); ++y)
        for (int x = 0; x < image.width(); ++x) {
            int r = 0, g = 0, b = 0;
            for (int dy = 0; dy < s; ++dy)
                for (int dx = 0; dx < s; ++dx) {
                    const Rgb c = canvas.colour[canvas.at(x * s + dx, y * s + dy)];
                    r += c.r, g += c.g, b += c.b;
                }
            image.set(x, y, {std::uint8_t((r + n / 2) / n), std::uint8_t((g + n / 2) / n), std::uint8_t((b + n / 2) / n)});
        }
    return image;
}

std::string format_value(double v) {
    if (v == 0) v = 0;  // no "-0"
    char text[32];
    if (std::fabs(v) >= 1000 && std::fabs(v) < 1e6) std::snprintf(text, sizeof text, "%.0f", v);
    else std::snprintf(text, sizeof text, "%.3g", v);
    return text;
}

// A pale panel behind text, so the text reads over fluid, floor or background alike.
void panel(Image& image, int x0, int y0, int x1, int y1) {
    for (int y = std::max(0, y0); y < std::min(image.height(), y1); ++y)
        for (int x = std::max(0, x0); x < std::min(image.width(), x1); ++x) image.blend(x, y, {255, 255, 255}, 0.72f);
}

// At the top right: the field's name, then a vertical colour bar with its top, middle and bottom
// values to its left.
void draw_legend(Image& image, const std::string& name, std::array<double, 2> range, int scale) {
    const Rgb ink{30, 32, 40};
    const int margin = 8 * scale, bar_w = 7 * scale, bar_h = std::max(40, int(0.4 * image.height()));
    const std::string labels[3] = {format_value(range[1]), format_value(0.5 * (range[0] + range[1])), format_value(range[0])};
    int label_w = 0;
    for (const std::string& l : labels) label_w = std::max(label_w, text_width(l, scale));
    const int line = text_height(scale), gap = 4 * scale;
    const int width = std::max(text_width(name, scale), label_w + gap + bar_w);
    const int x1 = image.width() - margin, x0 = x1 - width, y0 = margin;
    const int bar_x0 = x1 - bar_w, bar_y0 = y0 + (name.empty() ? 0 : line + gap);
    panel(image, x0 - gap, y0 - gap, x1 + gap, bar_y0 + bar_h + gap + line / 2);
    draw_text(image, x1 - text_width(name, scale), y0, name, ink, scale);
    for (int y = 0; y < bar_h; ++y)
        fill_rect(image, bar_x0, bar_y0 + y, x1, bar_y0 + y + 1, colour_map(1.0 - double(y) / (bar_h - 1)));
    for (int k = 0; k < 3; ++k) {
        // Text drawn from y starts with a row of blank font pixels; centre the glyphs on the tick.
        const int tick_y = bar_y0 + k * (bar_h - 1) / 2, text_y = tick_y - (7 * scale) / 2 - scale;
        draw_text(image, bar_x0 - gap - text_width(labels[k], scale), text_y, labels[k], ink, scale);
        fill_rect(image, bar_x0 - 2 * scale, tick_y, bar_x0, tick_y + scale, ink);
    }
}

void draw_caption(Image& image, const std::string& caption, int scale) {
    const int margin = 8 * scale, gap = 3 * scale;
    panel(image, margin - gap, margin - gap, margin + text_width(caption, scale) + gap, margin + text_height(scale));
    draw_text(image, margin, margin, caption, {30, 32, 40}, scale);
}

// The range with its ends made usable: finite, and apart (a single value gets a span of its own).
std::array<double, 2> widened(double lo, double hi) {
    if (!std::isfinite(lo) || !std::isfinite(hi)) return {0, 1};
    if (hi < lo) std::swap(lo, hi);
    if (hi - lo > 1e-12 * std::max({1.0, std::fabs(lo), std::fabs(hi)})) return {lo, hi};
    // A single value sits mid-range, except that a range never crosses zero on its account: a
    // fluid at rest shows speeds 0 to 0.5, not -0.5 to 0.5.
    const double half = std::max(0.05 * std::fabs(lo), 0.5);
    if (lo == 0) return {0, half};
    return {lo > 0 ? std::max(0.0, lo - half) : lo - half, lo < 0 ? std::min(0.0, lo + half) : lo + half};
}

void check_frame(const PreviewFrame& frame, const PreviewStyle& style) {
    const std::size_t n = frame.kinds.size();
    if (frame.positions.size() != 3 * n || (!frame.values.empty() && frame.values.size() != n))
        throw std::invalid_argument("preview: " + std::to_string(n) + " particle kinds, " +
                                    std::to_string(frame.positions.size()) + " position coordinates and " +
                                    std::to_string(frame.values.size()) + " values (want 3 coordinates and 1 value per kind)");
    if (!(frame.particle_radius > 0) || !std::isfinite(frame.particle_radius))
        throw std::invalid_argument("preview: the particle radius must be positive");
    for (const PreviewMesh& mesh : frame.meshes) {
        const std::size_t vertices = mesh.vertices.size() / 3;
        if (mesh.vertices.size() % 3 != 0 || mesh.triangles.size() % 3 != 0)
            throw std::invalid_argument("preview: a mesh's vertices and triangles come in threes");
        for (std::uint32_t v : mesh.triangles)
            if (v >= vertices)
                throw std::invalid_argument("preview: a mesh's triangle names vertex " + std::to_string(v) + " of " +
                                            std::to_string(vertices));
    }
    if (style.supersample < 1 || style.supersample > 4)
        throw std::invalid_argument("preview: supersample must be 1 to 4");
    if (style.width < 16 || style.height < 16 || style.width * style.supersample > 16384 ||
        style.height * style.supersample > 16384)
        throw std::invalid_argument("preview: the picture's sides must be 16 pixels or more, and 16384 or fewer "
                                    "once supersampled");
}

}  // namespace

std::array<double, 2> preview_field_range(const PreviewFrame& frame) {
    std::vector<float> v;
    for (std::size_t i = 0; i < frame.values.size() && i < frame.kinds.size(); ++i)
        if (frame.kinds[i] == PreviewKind::fluid && std::isfinite(frame.values[i])) v.push_back(frame.values[i]);
    if (v.empty()) return {0, 1};
    const std::size_t lo_at = std::size_t(std::floor(0.01 * double(v.size() - 1)));
    const std::size_t hi_at = std::size_t(std::ceil(0.99 * double(v.size() - 1)));
    std::nth_element(v.begin(), v.begin() + std::ptrdiff_t(lo_at), v.end());
    const double lo = v[lo_at];
    std::nth_element(v.begin() + std::ptrdiff_t(lo_at), v.begin() + std::ptrdiff_t(hi_at), v.end());
    const double hi = v[hi_at];
    if (hi > lo) return {lo, hi};
    const auto [min, max] = std::minmax_element(v.begin(), v.end());
    return widened(*min, *max);
}

PreviewCamera default_camera(const PreviewVec& domain_lo, const PreviewVec& domain_hi, double aspect, bool head_on) {
    if (!(aspect > 0) || !std::isfinite(aspect)) aspect = 16.0 / 9.0;
    D3 lo = d3(domain_lo), hi = d3(domain_hi);
    const double size = std::max(norm(hi - lo), 1e-6);
    PreviewCamera camera;
    camera.fov_y_degrees = 35;
    // 30 degrees round from the front (+z) toward +x and 28 above the horizon: the front, the
    // right-hand side and the floor all show, none edge-on.
    const double azimuth = head_on ? 0.0 : 30 * kPi / 180, elevation = head_on ? 0.0 : 28 * kPi / 180;
    const D3 toward_eye{std::sin(azimuth) * std::cos(elevation), std::sin(elevation), std::cos(azimuth) * std::cos(elevation)};
    D3 target = 0.5 * (lo + hi);
    const double tan_y = std::tan(0.5 * camera.fov_y_degrees * kPi / 180), tan_x = tan_y * aspect;
    // Head-on (a 2D scene's plane, often wide), the box is fitted left of the legend, which
    // takes the picture's right-hand `legend` share: picture x in [-1, 1 - 2 legend] maps to
    // [-1, 1] below.
    const double legend = head_on ? 0.15 : 0.0;
    const auto left_of_legend = [&](double x) { return (x + legend) / (1 - legend); };
    // The corners' extent in the picture, as a fraction of its half-size (1: touching an edge), and
    // where the middle of their bounding rectangle lies in the same units.
    const auto fit = [&](double distance, D3 aim, double* mid_x, double* mid_y) {
        camera.target = {aim.x, aim.y, aim.z};
        const D3 eye = aim + distance * toward_eye;
        camera.eye = {eye.x, eye.y, eye.z};
        const Projector view = make_projector(camera, 2, 2);
        double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
        for (int k = 0; k < 8; ++k) {
            const D3 c = view.to_camera({k & 1 ? hi.x : lo.x, k & 2 ? hi.y : lo.y, k & 4 ? hi.z : lo.z});
            if (c.z <= 0) return 1e300;
            const double x = left_of_legend(c.x / c.z / tan_x);
            x0 = std::min(x0, x), x1 = std::max(x1, x);
            y0 = std::min(y0, c.y / c.z / tan_y), y1 = std::max(y1, c.y / c.z / tan_y);
        }
        if (mid_x) *mid_x = 0.5 * (x0 + x1), *mid_y = 0.5 * (y0 + y1);
        return std::max({-x0, x1, -y0, y1});
    };
    // A few rounds of: the distance at which the box fills 90% of the picture (bisection: the
    // extent shrinks as the eye backs away), then a pan that centres the box.
    double distance = size;
    for (int round = 0; round < 4; ++round) {
        double near = 1e-3 * size, far = 1e3 * size;
        for (int k = 0; k < 100; ++k) {
            distance = 0.5 * (near + far);
            (fit(distance, target, nullptr, nullptr) > 0.9 ? near : far) = distance;
        }
        distance = far;
        double mid_x = 0, mid_y = 0;
        fit(distance, target, &mid_x, &mid_y);
        const Projector view = make_projector(camera, 2, 2);
        const double depth = distance;  // the target's depth: a shift there moves the box by mid * tan * depth
        target = target + (mid_x * (1 - legend) * tan_x * depth) * view.right + (mid_y * tan_y * depth) * view.up;
    }
    fit(distance, target, nullptr, nullptr);
    return camera;
}

Image render_preview(const PreviewFrame& frame, const PreviewCamera& camera, const PreviewStyle& style) {
    check_frame(frame, style);
    const int s = style.supersample;
    Canvas canvas{style.width * s, style.height * s, {}, {}};
    canvas.colour.resize(std::size_t(canvas.width) * std::size_t(canvas.height));
    canvas.depth.assign(canvas.colour.size(), std::numeric_limits<float>::infinity());
    fill_background(canvas, style.background_top, style.background_bottom);
    const Projector view = make_projector(camera, canvas.width, canvas.height);
    const std::array<double, 2> range =
        frame.field_range ? widened((*frame.field_range)[0], (*frame.field_range)[1]) : preview_field_range(frame);

    const std::vector<Splat> splats = project_particles(frame, style, view, canvas, range);
    draw_in_bands(splats, canvas.height,
                  [&](const Splat& splat, int r0, int r1) { draw_splat(canvas, splat, r0, r1, style.ambient); });

    std::vector<ScreenTriangle> opaque, translucent;
    std::vector<PreviewMesh> floor;
    if (frame.domain) floor = floor_meshes((*frame.domain)[0], (*frame.domain)[1], style);
    for (const PreviewMesh& mesh : floor) add_mesh(opaque, mesh, view, canvas);
    for (const PreviewMesh& mesh : frame.meshes) add_mesh(mesh.opacity >= 1 ? opaque : translucent, mesh, view, canvas);
    draw_opaque(canvas, opaque, style.ambient);
    if (frame.domain) draw_box_edges(canvas, view, (*frame.domain)[0], (*frame.domain)[1], style.edge_colour, s);
    draw_translucent(canvas, translucent, style.ambient);

    Image image = downsample(canvas, s);
    const int text_scale = std::max(1, style.height / 270);
    const bool any_fluid = std::find(frame.kinds.begin(), frame.kinds.end(), PreviewKind::fluid) != frame.kinds.end();
    if (style.show_legend && !frame.values.empty() && any_fluid) draw_legend(image, frame.field_name, range, text_scale);
    if (!frame.caption.empty()) draw_caption(image, frame.caption, text_scale);
    return image;
}

}  // namespace mw
