// The regular lattice at spacing r0 on which IBPs live.
//
// Anchoring: along each axis the lattice is centred on the mesh's bounding box and holds
// n = round(L / r0) points (at least 1), so the first and last points lie (L - (n-1) r0) / 2 inside
// the faces, an offset between r0/4 and 3r0/4. For a box whose sides are an integer number of r0
// that offset is exactly r0/2: full layers, each IBP the centre of an r0-cube of the solid, so the
// IBP count times r0^3 is the box volume, and a wall k r0 thick (aligned with the box) holds k
// layers. Centring keeps symmetric shapes symmetric, and rounding (rather than flooring) makes the
// IBP volume of a box unbiased when its sides are not multiples of r0.
#pragma once
#include <array>
#include <cmath>
#include <cstdint>

#include "sampling/mesh.hpp"

namespace mw {

struct LatticeGrid {
    Vec3d origin{0, 0, 0};  // position of lattice point (0, 0, 0)
    double spacing = 1;
    std::array<int, 3> dims{0, 0, 0};

    std::size_t count() const { return std::size_t(dims[0]) * std::size_t(dims[1]) * std::size_t(dims[2]); }
    bool contains(int i, int j, int k) const {
        return i >= 0 && j >= 0 && k >= 0 && i < dims[0] && j < dims[1] && k < dims[2];
    }
    std::size_t index(int i, int j, int k) const {
        return (std::size_t(k) * std::size_t(dims[1]) + std::size_t(j)) * std::size_t(dims[0]) + std::size_t(i);
    }
    Vec3d position(int i, int j, int k) const { return origin + spacing * Vec3d(i, j, k); }
};

inline LatticeGrid make_lattice_grid(const Aabb& box, double spacing) {
    LatticeGrid g;
    g.spacing = spacing;
    const Vec3d e = box.extent();
    for (int a = 0; a < 3; ++a) {
        // 1e-9 guards the round-half case against rounding noise in L / r0.
        const int n = std::max(1, static_cast<int>(std::floor(e[a] / spacing + 0.5 + 1e-9)));
        g.dims[a] = n;
        g.origin[a] = box.center()[a] - 0.5 * (n - 1) * spacing;
    }
    return g;
}

}  // namespace mw
