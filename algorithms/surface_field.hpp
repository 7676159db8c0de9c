// The fluid's colour field on a box of grid nodes, for surface reconstruction (surface/): at each
// node x, c(x) = Σ_j W(x - x_j) / S over the fluid particles j, where S is Σ W over the prototype
// lattice (pcisph_delta.hpp), so that c is 1 inside fluid at rest and falls to 0 one support
// radius outside it. The surface is the level set c = iso, with iso chosen so that a flat face
// of fluid at rest sits r0/2 outside its last layer of particles: the volume the particles stand
// for (each r0³), not the volume their centres span.
//
// Computed on the device from the neighbour grid, at frame times only; the result is the one
// host copy (the mesher needs it there).
#pragma once
#include <cmath>
#include <cstdint>

#include <vector>

#include "algorithms/module.hpp"
#include "algorithms/neighbor_search.hpp"
#include "algorithms/pcisph_delta.hpp"

MW_BACKEND_BEGIN

// Nodes per axis of the blocks compute_color_field works on.
constexpr int kColorBlock = 4;

// c(x) at every node of `nodes` (x fastest, then y, then z), from the fluid particles in the
// grid's cells: the grid must have been built from the current positions.
//
// One work item per block of kColorBlock³ nodes: it visits the fluid particles of the cells
// within h of the block once, and adds each particle within h of the block's box to all of the
// block's nodes (W is 0 beyond h by itself). A fixed count of kernel evaluations per particle,
// with no branch per node, the compiler unrolls; on the development VM this took a quarter of the
// time of a gather per node over its 27 cells, and half that of visiting only the nodes within h
// of each particle (their counts vary from row to row, and the branches mispredict once the
// particles have left their lattice). The sums run in a fixed order (cells, then particles in
// store order), so the field is reproducible on any thread count, and no node is written twice.
template <class Kernel>
void compute_color_field(const DeviceContext& device, const GridView& grid, View<const Vec3> position,
                         const Kernel& kernel, Real inverse_lattice_sum, const SurfaceNodes& nodes,
                         View<Real> color) {
    const int blocks[3] = {(nodes.dims[0] + kColorBlock - 1) / kColorBlock,
                           (nodes.dims[1] + kColorBlock - 1) / kColorBlock,
                           (nodes.dims[2] + kColorBlock - 1) / kColorBlock};
    const std::size_t block_count = std::size_t(blocks[0]) * std::size_t(blocks[1]) * std::size_t(blocks[2]);
    const SurfaceNodes n = nodes;
    parallel_for(device, "surface_color_field", block_count, [=] MW_HD(std::size_t b) {
        const int bi = int(b % std::size_t(blocks[0])), bj = int((b / std::size_t(blocks[0])) % std::size_t(blocks[1])),
                  bk = int(b / (std::size_t(blocks[0]) * std::size_t(blocks[1])));
        const int lo[3] = {bi * kColorBlock, bj * kColorBlock, bk * kColorBlock};
        int hi[3];  // last node of the block on each axis
        for (int a = 0; a < 3; ++a) hi[a] = (lo[a] + kColorBlock < n.dims[a] ? lo[a] + kColorBlock : n.dims[a]) - 1;
        const Real origin[3] = {n.origin.x, n.origin.y, n.origin.z};
        const Real grid_origin[3] = {grid.shape.origin.x, grid.shape.origin.y, grid.shape.origin.z};
        const Real h = kernel.h, h2 = h * h;
        // The cells within h of the block (clamped to the grid: fluid outside it is in none).
        int cell_lo[3], cell_hi[3];
        for (int a = 0; a < 3; ++a) {
            const Real first = (origin[a] + Real(lo[a]) * n.spacing - h - grid_origin[a]) * grid.shape.inv_cell;
            const Real last = (origin[a] + Real(hi[a]) * n.spacing + h - grid_origin[a]) * grid.shape.inv_cell;
            cell_lo[a] = first > Real(0) ? int(first) : 0;
            cell_hi[a] = last < Real(grid.shape.dims[a] - 1) ? int(last) : grid.shape.dims[a] - 1;
        }
        Real sum[kColorBlock * kColorBlock * kColorBlock];
        for (int k = 0; k < kColorBlock * kColorBlock * kColorBlock; ++k) sum[k] = 0;
        for (int cz = cell_lo[2]; cz <= cell_hi[2]; ++cz)
            for (int cy = cell_lo[1]; cy <= cell_hi[1]; ++cy)
                for (int cx = cell_lo[0]; cx <= cell_hi[0]; ++cx) {
                    const int c[3] = {cx, cy, cz};
                    const std::uint32_t cell = grid.shape.linear(c);
                    for (std::uint32_t j = grid.begin[cell], e = grid.end[cell]; j < e; ++j) {
                        const Vec3 x = position[j];
                        const Real p[3] = {x.x, x.y, x.z};
                        // Skipped unless within h of the box the block's nodes span.
                        Real gap2 = 0;
                        for (int a = 0; a < 3; ++a) {
                            const Real below = origin[a] + Real(lo[a]) * n.spacing - p[a];
                            const Real above = p[a] - origin[a] - Real(hi[a]) * n.spacing;
                            const Real gap = below > Real(0) ? below : (above > Real(0) ? above : Real(0));
                            gap2 += gap * gap;
                        }
                        if (gap2 >= h2) continue;
                        for (int k = 0; k < kColorBlock; ++k) {
                            const Real dz = origin[2] + Real(lo[2] + k) * n.spacing - p[2];
                            for (int jj = 0; jj < kColorBlock; ++jj) {
                                const Real dy = origin[1] + Real(lo[1] + jj) * n.spacing - p[1];
                                const Real dyz2 = dy * dy + dz * dz;
                                const int row = (k * kColorBlock + jj) * kColorBlock;
                                for (int i = 0; i < kColorBlock; ++i) {
                                    const Real dx = origin[0] + Real(lo[0] + i) * n.spacing - p[0];
                                    sum[row + i] += kernel.W_r2(dx * dx + dyz2);
                                }
                            }
                        }
                    }
                }
        const std::size_t nx = std::size_t(n.dims[0]), nxy = nx * std::size_t(n.dims[1]);
        for (int k = lo[2]; k <= hi[2]; ++k)
            for (int jj = lo[1]; jj <= hi[1]; ++jj)
                for (int i = lo[0]; i <= hi[0]; ++i)
                    color[std::size_t(k) * nxy + std::size_t(jj) * nx + std::size_t(i)] =
                        sum[((k - lo[2]) * kColorBlock + (jj - lo[1])) * kColorBlock + (i - lo[0])] * inverse_lattice_sum;
    });
}

MW_BACKEND_END

namespace mw {

// The colour field's value r0/2 outside a flat face of the prototype lattice (layers at
// z = 0, -r0, -2 r0, ...), averaged over 8 x 8 places across one lattice cell of the face; in 2D
// outside a flat edge (rows at y = 0, -r0, ...), over 8 places along one cell of it.
template <class Kernel>
double surface_iso_value(const Kernel& kernel, double spacing) {
    const double lattice_sum = prototype_sums(kernel, spacing, Kernel::kDimensions).sum_W;
    const int reach = static_cast<int>(std::ceil(kernel.h / spacing)) + 2;
    constexpr int kPlaces = 8;
    double total = 0;
    if constexpr (Kernel::kDimensions == 2) {
        for (int a = 0; a < kPlaces; ++a) {
            const double px = spacing * (a + 0.5) / kPlaces, py = 0.5 * spacing;
            double sum = 0;
            for (int j = -reach; j <= 0; ++j)
                for (int i = -reach; i <= reach; ++i) {
                    const double dx = px - i * spacing, dy = py - j * spacing;
                    const double r = std::sqrt(dx * dx + dy * dy);
                    if (r < kernel.h) sum += kernel.W(Real(r));
                }
            total += sum / lattice_sum;
        }
        return total / kPlaces;
    } else {
        for (int a = 0; a < kPlaces; ++a)
            for (int b = 0; b < kPlaces; ++b) {
                const double px = spacing * (a + 0.5) / kPlaces, py = spacing * (b + 0.5) / kPlaces, pz = 0.5 * spacing;
                double sum = 0;
                for (int k = -reach; k <= 0; ++k)
                    for (int j = -reach; j <= reach; ++j)
                        for (int i = -reach; i <= reach; ++i) {
                            const double dx = px - i * spacing, dy = py - j * spacing, dz = pz - k * spacing;
                            const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
                            if (r < kernel.h) sum += kernel.W(Real(r));
                        }
                total += sum / lattice_sum;
            }
        return total / (kPlaces * kPlaces);
    }
}

}  // namespace mw

MW_BACKEND_BEGIN

// The surface field module: the colour field at frame times (no stage), and its nodes' buffer,
// sized by the largest node box asked for so far.
template <class Kernel>
class SurfaceField final : public Module {
   public:
    SurfaceField(SimulationState<Kernel>& state, NeighborSearch<Kernel>& search) : state_(state), search_(search) {}

    // The field at `nodes`, copied into `color`, and its iso-value. The particles have moved since
    // this step's sort; a sort now (a stable sort by the keys the next step would compute) leaves
    // the next step's sort nothing to reorder, so a run with surfaces takes the same steps.
    void compute(const SurfaceNodes& nodes, std::vector<Real>& color, double& iso) {
        search_.sort();
        color_.resize(nodes.count());
        // The mass is rho0 over the lattice's sum of W (pcisph_delta.hpp): m / rho0 normalises the field.
        compute_color_field(state_.device, search_.grid(), state_.store.position.cview(), state_.fluid.kernel,
                            state_.fluid.mass / state_.fluid.rest_density, nodes, color_.view());
        color_.download(color);
        iso = surface_iso_value(state_.fluid.kernel, double(state_.params.fluid.spacing));  // a few thousand kernel values
    }
    std::size_t bytes() const override { return color_.bytes(); }

   private:
    SimulationState<Kernel>& state_;
    NeighborSearch<Kernel>& search_;
    DeviceArray<Real> color_;
};

MW_BACKEND_END
