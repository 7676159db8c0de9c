// A signed distance on a regular grid, read in kernels: trilinear between nodes, with the
// gradient of that interpolation. The grids of static mesh objects are built once on the host
// (sampling/signed_distance.hpp) and read by the velocity–position correction (wall_contact.hpp).
#pragma once
#include <cstdint>

#include "algorithms/vec3.hpp"
#include "backend/view.hpp"

namespace mw {

struct DistanceField {
    Vec3 origin{0, 0, 0};  // node (0, 0, 0)
    Real inv_spacing = 1;
    std::int32_t nx = 0, ny = 0, nz = 0;  // nodes per axis, at least 2 each
    std::uint32_t first = 0;              // node (0, 0, 0)'s entry in the values array; x fastest, then y, z

    // The distance at x and its gradient (the interpolation's, so |gradient| is about 1 near the
    // surface and exactly 1 where the surface is flat across a cell). False, with nothing written,
    // when x lies outside the grid or is not finite.
    MW_INLINE bool sample(View<const Real> values, Vec3 x, Real& distance, Vec3& gradient) const {
        const Real px = (x.x - origin.x) * inv_spacing, py = (x.y - origin.y) * inv_spacing,
                   pz = (x.z - origin.z) * inv_spacing;
        // Written so that NaN fails too.
        if (!(px >= Real(0) && py >= Real(0) && pz >= Real(0) && px <= Real(nx - 1) && py <= Real(ny - 1) &&
              pz <= Real(nz - 1)))
            return false;
        // The cell, its last one holding the grid's far faces.
        const std::int32_t i = cell(px, nx), j = cell(py, ny), k = cell(pz, nz);
        const Real fx = px - Real(i), fy = py - Real(j), fz = pz - Real(k);
        const std::size_t row = std::size_t(nx), slab = std::size_t(nx) * std::size_t(ny);
        const std::size_t base = first + std::size_t(k) * slab + std::size_t(j) * row + std::size_t(i);
        const Real v000 = values[base], v100 = values[base + 1];
        const Real v010 = values[base + row], v110 = values[base + row + 1];
        const Real v001 = values[base + slab], v101 = values[base + slab + 1];
        const Real v011 = values[base + slab + row], v111 = values[base + slab + row + 1];
        // Along x first, on the cell's four x-edges; then y, then z.
        const Real e00 = v000 + fx * (v100 - v000), e10 = v010 + fx * (v110 - v010);
        const Real e01 = v001 + fx * (v101 - v001), e11 = v011 + fx * (v111 - v011);
        const Real f0 = e00 + fy * (e10 - e00), f1 = e01 + fy * (e11 - e01);
        distance = f0 + fz * (f1 - f0);
        const Real gx0 = (v100 - v000) + fy * ((v110 - v010) - (v100 - v000));
        const Real gx1 = (v101 - v001) + fy * ((v111 - v011) - (v101 - v001));
        gradient = inv_spacing * Vec3{gx0 + fz * (gx1 - gx0), (e10 - e00) + fz * ((e11 - e01) - (e10 - e00)), f1 - f0};
        return true;
    }

   private:
    static MW_INLINE std::int32_t cell(Real p, std::int32_t n) {
        const std::int32_t c = static_cast<std::int32_t>(p);
        return c < n - 2 ? c : n - 2;
    }
};

}  // namespace mw
