// The neighbour search module: the grid over the domain (neighbor_grid.hpp), built once for the
// static boundary and every step for the moving particles, and, where the scene uses them,
// per-step neighbour lists for the fluid (neighbor_list.hpp). Stage "neighbors".
#pragma once
#include <functional>
#include <vector>

#include "algorithms/module.hpp"

MW_BACKEND_BEGIN

template <class Kernel>
class NeighborSearch final : public Module {
   public:
    // The grid covers [lo, hi] (the domain, and every static particle) and one support radius more;
    // fluid that leaves it is counted as lost. `arriving`: fluid particles that appear at run time
    // (emitters, melting), for whom the lists keep rows from the start.
    NeighborSearch(SimulationState<Kernel>& state, Vec3 lo, Vec3 hi, long arriving)
        : state_(state), grid_(state.device), lists_(state.device), arriving_(arriving) {
        const SimulationParams& params = state.params;
        const Real h = state.fluid.kernel.h;
        // In 2D everything lies in the plane z = lo.z = hi.z: one layer of cells, so that a
        // particle's neighbourhood is 3 x 3 cells (and its Z-order a 2D one), not 3 x 3 x 2.
        const Real hz = Kernel::kDimensions == 2 ? Real(0) : h;
        grid_.configure(Vec3{lo.x - h, lo.y - h, lo.z - hz}, Vec3{hi.x + h, hi.y + h, hi.z + hz}, h,
                        params.neighbors.ordering, params.neighbors.cells_per_support);
        use_lists_ = state.has_fluid && (params.neighbors.lists == NeighborParams::Lists::kAuto
                                             ? kPrefersNeighborLists
                                             : params.neighbors.lists == NeighborParams::Lists::kOn);
        if (use_lists_) {
            // Registered before the first sort, so that it travels with the particles from the
            // start; 0 makes the first build lay its rows out from exact counts (one second fill).
            // A checkpoint without it (written on a backend without lists) starts from 0 too.
            neighbor_count_ = &state.store.template add<std::uint32_t>("neighbor_count", FieldLife::kPersistent, true);
            neighbor_count_->fill(0);
        }
    }

    // Called after every sort, before anything else reads the new order (solid_bodies.hpp: the
    // slot map).
    void on_sorted(std::function<void()> f) { after_sort_.push_back(std::move(f)); }

    // Sorts the static boundary once, into cells of its own: after every module has registered
    // its store fields with their initial values, since it permutes them all.
    void sort_static() { grid_.build_static(state_.store); }

    // Sorts the moving particles by (group, cell), permutes the store and rebuilds the cell ranges.
    GroupRanges sort() {
        ranges_ = grid_.build(state_.store);
        for (const auto& f : after_sort_) f();
        return ranges_;
    }
    // The groups' ranges after the last sort.
    const GroupRanges& last_ranges() const { return ranges_; }

    void bind(StepPlan& plan) override {
        plan.bind("neighbors", [this](StepContext& step) { search(step); });
    }

    // The first sort, and the lists sized for the fluid to come, before the first step.
    void start(const StepContext& first) override {
        if (!use_lists_) return;
        // Fluid that arrives at run time gets rows without reallocating.
        if (arriving_ > 0) lists_.reserve(first.ranges.fluid_end + std::size_t(arriving_));
    }

    // A step's search: the sort, then the lists of pairs within h at the start of the step, as
    // SPlisHSPlasH builds them. A pair that comes within h while PCISPH predicts is left out: its
    // weight is at most W(h - d), of order (d/h)^3, for the d <= dt |v_i - v_j| it moved. A skin of
    // 2 dt v_max would have doubled the lists (and the PCISPH time) in the fast phase of a dam break
    // for no change in the density error (docs/solver.md).
    void search(StepContext& step) {
        step.ranges = sort();
        step.neighbors = build_lists(step.ranges);
    }

    // The lists over the current order (none without them), and the neighbourhood to gather from.
    Neighborhood build_lists(const GroupRanges& ranges) {
        Neighborhood n;
        n.grid = grid_.view();
        n.use_lists = use_lists_;
        if (use_lists_) {
            lists_.build(n.grid, ranges.fluid_end, state_.store.position.cview(), state_.fluid.kernel.h,
                         neighbor_count_->view());
            n.lists = lists_.view();
        }
        return n;
    }

    GridView grid() const { return grid_.view(); }
    bool uses_lists() const { return use_lists_; }
    std::size_t bytes() const override { return grid_.bytes() + lists_.bytes(); }
    void load(const StateArchive& in) override {
        if (neighbor_count_ && !in.has("store.neighbor_count")) neighbor_count_->fill(0);
    }

   private:
    SimulationState<Kernel>& state_;
    NeighborGrid grid_;
    NeighborList lists_;
    bool use_lists_ = false;
    long arriving_ = 0;
    GroupRanges ranges_;
    DeviceArray<std::uint32_t>* neighbor_count_ = nullptr;  // store field: each particle's list length
    std::vector<std::function<void()>> after_sort_;
};

MW_BACKEND_END
