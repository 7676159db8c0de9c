// The boundary volumes module: Akinci's volume V_b of every boundary particle (Akinci et al.
// 2012), which weighs its share in the fluid's density and forces. The static boundary's are
// computed once at set-up; the moving solids' every step (stage "solid_volumes"), as their
// particles spread and bunch up.
//
// A melting object is a lattice at the fluid's spacing that fills its volume (docs/melting.md), as
// a block of fluid would: each of its particles weighs a fluid particle's volume m/ρ0. Akinci's
// volume would swell its outer layers, which stand in for layers missing behind a single-layer
// boundary; behind a lattice's face those layers exist, and fluid one spacing from the face read
// 8% over-dense per face (16% between two lattices), enough to spray each newly melted particle
// out of the gap it melted in (tests/core/test_stefan.cpp).
#pragma once
#include <limits>
#include <vector>

#include "algorithms/module.hpp"
#include "simulation/simulation.hpp"

MW_BACKEND_BEGIN

// Whether a fluid particle in the cells around x lies closer than sqrt(reach2): stops at the first.
MW_INLINE bool fluid_within(const GridView& grid, View<const Vec3> position, Vec3 x, Real reach2) {
    int c[3];
    grid.shape.clamped_cell_of(x, c);
    const int r = grid.shape.reach;
    for (int dz = -r; dz <= r; ++dz)
        for (int dy = -r; dy <= r; ++dy)
            for (int dx = -r; dx <= r; ++dx) {
                const int cc[3] = {c[0] + dx, c[1] + dy, c[2] + dz};
                if (cc[0] < 0 || cc[1] < 0 || cc[2] < 0 || cc[0] >= grid.shape.dims[0] || cc[1] >= grid.shape.dims[1] ||
                    cc[2] >= grid.shape.dims[2])
                    continue;
                const std::uint32_t cell = grid.shape.linear(cc);
                for (std::uint32_t i = grid.begin[cell], e = grid.end[cell]; i < e; ++i)
                    if (norm2(position[i] - x) < reach2) return true;
            }
    return false;
}

// Akinci boundary volume V_b = 1 / Σ_k W(x_b - x_k) over boundary neighbours k (b included), for
// particles [first, first + count). Static particles see static neighbours only (computed once);
// moving solids see moving solids and static walls. Branch-free terms (W_r2 is 0 out of range by
// itself), as in the PCISPH sums: a boundary particle's neighbourhood is dense (walls at r0/2), and
// whether a candidate is in range is unpredictable (a distance test before each term made the
// moving solids' volumes of scenes/thin_box_pour.json 27% slower on OpenMP, though five in six of
// the candidates lie beyond h; heat.hpp's grid rows, which read more per candidate, gain from
// it). A particle of an object flagged in
// `lattice_object` (indexed by object, empty for static particles) weighs `lattice_volume`.
//
// `read_reach2` > 0 (moving solids without heat): only a particle that some fluid particle reads
// gets its volume, the others 0. The fluid reads b in its density, pressure, viscosity and tension
// sums, and the reaction reads b's own, only where a fluid particle lies in b's 27 cells (grid
// mode: the relation is symmetric) or within h of it (lists, built every step with the same test):
// `read_reach2` is h² with lists and any distance on the grid. Inside a large object, and before
// the fluid arrives, that is most of its particles (tests/core/test_kernels.cpp checks the volumes
// read are unchanged). Lists kept with a skin (pairs beyond h, for later steps) would need
// `read_reach2` widened by the same skin.
template <class Kernel>
void compute_boundary_volumes(const DeviceContext& device, GridView grid, View<const Vec3> position, View<Real> volume, std::size_t first,
                              std::size_t count, bool moving, Kernel kernel, View<const std::int32_t> object = {},
                              View<const std::uint8_t> lattice_object = {}, Real lattice_volume = 0,
                              Real read_reach2 = 0) {
    parallel_for(device, "boundary_volume", count, [=] MW_HD(std::size_t k) {
        const std::size_t b = first + k;
        if (read_reach2 > Real(0) && !fluid_within(grid, position, position[b], read_reach2)) {
            volume[b] = 0;
            return;
        }
        if (lattice_object.size() != 0) {
            const std::int32_t o = object[b];
            if (o >= 0 && std::size_t(o) < lattice_object.size() && lattice_object[std::size_t(o)]) {
                volume[b] = lattice_volume;
                return;
            }
        }
        const Vec3 xb = position[b];
        Real sum = 0;
        auto add = [&](std::uint32_t j) { sum += kernel.W_r2(norm2(xb - position[j])); };
        grid.for_each_static(xb, add);
        if (moving) grid.for_each_solid(xb, add);
        volume[b] = sum > Real(0) ? Real(1) / sum : Real(0);
    });
}

template <class Kernel>
class BoundaryVolumes final : public Module {
   public:
    // `moving_solids`: the scene has elastic or rigid objects; `heat`: it conducts heat, which
    // reads the solids' volumes even without fluid.
    BoundaryVolumes(SimulationState<Kernel>& state, const SimulationSetup& setup, bool moving_solids, bool heat)
        : state_(state), moving_solids_(moving_solids), per_step_(moving_solids && state.has_fluid), all_moving_(heat) {
        const ParticleStore& store = state.store;
        // Only fluid next to boundary particles reads them: without fluid (but for heat), or
        // without any boundary particle, they are neither stored nor computed. Indexed like the
        // store (fluid entries unused), so that a particle changing type (melting) needs no
        // re-indexing.
        const bool for_fluid = state.has_fluid && (store.static_count() > 0 || moving_solids);
        if (for_fluid || (heat && moving_solids)) volume_.resize(store.size());
        std::vector<std::uint8_t> lattice(setup.solids.size(), 0);
        bool any_lattice = false;
        for (std::size_t k = 0; k < setup.solids.size(); ++k) any_lattice |= (lattice[k] = setup.solids[k].melts() ? 1 : 0) != 0;
        if (any_lattice) lattice_object_.upload(lattice);
        lattice_volume_ = state.fluid.mass / state.fluid.rest_density;
    }

    // The static boundary's volumes, once: they see static neighbours only.
    void start(const StepContext& first) override {
        const ParticleStore& store = state_.store;
        if (state_.has_fluid && store.static_count() > 0)
            compute_boundary_volumes(state_.device, first.neighbors.grid, store.position.cview(), volume_.view(),
                                     store.moving_count(), store.static_count(), false, state_.fluid.kernel);
    }

    void bind(StepPlan& plan) override {
        if (per_step_)
            plan.bind("solid_volumes", [this](StepContext& step) {
                update_moving(step.neighbors.grid, step.ranges, step.neighbors.use_lists);
            });
    }

    // The moving solids' boundary particles' volumes, over the current grid: with heat all of
    // them (it conducts between solid particles), otherwise those the fluid reads (`lists`: the
    // fluid's neighbour lists, else the grid, gather them).
    void update_moving(const GridView& grid, const GroupRanges& ranges, bool lists = false) {
        const Real h = state_.fluid.kernel.h;
        const Real read_reach2 = all_moving_ ? Real(0) : lists ? h * h : std::numeric_limits<Real>::max();
        compute_boundary_volumes(state_.device, grid, state_.store.position.cview(), volume_.view(), ranges.fluid_end,
                                 ranges.solid_end - ranges.fluid_end, true, state_.fluid.kernel, state_.store.object.cview(),
                                 lattice_object_.cview(), lattice_volume_, read_reach2);
    }
    bool moving_solids() const { return moving_solids_; }
    // Whether the step keeps them current (fluid and moving solids).
    bool updated_every_step() const { return per_step_; }
    View<const Real> volumes() const { return volume_.cview(); }
    std::size_t bytes() const override { return volume_.bytes() + lattice_object_.bytes(); }

   private:
    SimulationState<Kernel>& state_;
    bool moving_solids_ = false, per_step_ = false;
    bool all_moving_ = false;                    // heat reads every moving particle's volume
    DeviceArray<Real> volume_;                   // V_b, indexed like the store
    DeviceArray<std::uint8_t> lattice_object_;   // per object: 1 for a melting object's lattice (empty: none)
    Real lattice_volume_ = 0;                    // a fluid particle's volume m/ρ0
};

MW_BACKEND_END
