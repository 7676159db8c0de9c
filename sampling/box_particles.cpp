#include "sampling/box_particles.hpp"

#include <cmath>
#include <string>

#include "common/errors.hpp"

namespace mw {

namespace {
void check_box(Vec3 lo, Vec3 hi, Real spacing, const char* what, int dimensions = 3) {
    if (!(spacing > 0)) throw InputError(std::string(what) + ": spacing must be positive");
    if (dimensions != 2 && dimensions != 3) throw InputError(std::string(what) + ": dimensions must be 2 or 3");
    if (!(hi.x > lo.x && hi.y > lo.y && (dimensions == 2 || hi.z > lo.z)))
        throw InputError(std::string(what) + ": box max must exceed min on every axis");
}

// In 2D: x moved into the plane z = 0 (a box flat in z, whose surface add_box_surface makes an
// outline).
Vec3 flat_if(int dimensions, Vec3 x) { return dimensions == 2 ? Vec3{x.x, x.y, 0} : x; }

// Points of a regular grid on the surface of [lo, hi], about `spacing` apart (the spacing is
// adjusted per axis so the grid ends exactly on the faces); for a box flat in z, on its outline.
void add_box_surface(Vec3 lo, Vec3 hi, Real spacing, std::vector<Vec3>& out) {
    const Real extent[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
    int cells[3];
    Real step[3];
    for (int a = 0; a < 3; ++a) {
        cells[a] = extent[a] > 0 ? std::max(1, static_cast<int>(std::lround(extent[a] / spacing))) : 0;
        step[a] = cells[a] ? extent[a] / cells[a] : 0;
    }
    for (int k = 0; k <= cells[2]; ++k)
        for (int j = 0; j <= cells[1]; ++j)
            for (int i = 0; i <= cells[0]; ++i) {
                // A box with no extent in z is a rectangle, its surface its outline.
                const bool on_face = i == 0 || i == cells[0] || j == 0 || j == cells[1] ||
                                     (cells[2] != 0 && (k == 0 || k == cells[2]));
                if (on_face) out.push_back({lo.x + i * step[0], lo.y + j * step[1], lo.z + k * step[2]});
            }
}
}  // namespace

std::vector<Vec3> fill_box_lattice(Vec3 lo, Vec3 hi, Real spacing, int dimensions) {
    check_box(lo, hi, spacing, "fluid block", dimensions);
    if (dimensions == 2) {  // one layer at z = 0
        lo.z = -spacing / 2;
        hi.z = spacing / 2;
    }
    const int nx = static_cast<int>(std::floor((hi.x - lo.x) / spacing + 1e-4));
    const int ny = static_cast<int>(std::floor((hi.y - lo.y) / spacing + 1e-4));
    const int nz = static_cast<int>(std::floor((hi.z - lo.z) / spacing + 1e-4));
    std::vector<Vec3> points;
    points.reserve(static_cast<std::size_t>(nx) * ny * nz);
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i)
                points.push_back({lo.x + (i + Real(0.5)) * spacing, lo.y + (j + Real(0.5)) * spacing,
                                  lo.z + (k + Real(0.5)) * spacing});
    return points;
}

std::vector<Vec3> sample_container_walls(Vec3 lo, Vec3 hi, Real spacing, int layers, Real gap, int dimensions) {
    check_box(lo, hi, spacing, "domain walls", dimensions);
    if (layers < 1) throw InputError("domain walls: layers must be at least 1");
    if (!(gap >= 0)) throw InputError("domain walls: the gap outside the faces must be >= 0");
    std::vector<Vec3> points;
    for (int layer = 0; layer < layers; ++layer) {
        const Real d = gap + layer * spacing;
        add_box_surface(flat_if(dimensions, {lo.x - d, lo.y - d, lo.z - d}),
                        flat_if(dimensions, {hi.x + d, hi.y + d, hi.z + d}), spacing, points);
    }
    return points;
}

std::vector<Vec3> sample_solid_box(Vec3 lo, Vec3 hi, Real spacing, int layers, int dimensions) {
    check_box(lo, hi, spacing, "static box", dimensions);
    if (layers < 1) throw InputError("static box: layers must be at least 1");
    std::vector<Vec3> points;
    for (int layer = 0; layer < layers; ++layer) {
        const Real d = layer * spacing;
        const Vec3 a = flat_if(dimensions, {lo.x + d, lo.y + d, lo.z + d});
        const Vec3 b = flat_if(dimensions, {hi.x - d, hi.y - d, hi.z - d});
        if (b.x < a.x || b.y < a.y || b.z < a.z) break;  // the box is full
        add_box_surface(a, b, spacing, points);
    }
    return points;
}

}  // namespace mw
