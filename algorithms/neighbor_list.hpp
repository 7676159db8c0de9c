// Per-step neighbour lists for fluid particles (CSR): every fluid and boundary particle within
// h of fluid particle i at the start of the step, fluid neighbours first. Built once per
// step from the grid (count, scan, fill: exact, no cap), then read by every PCISPH iteration,
// so the 27-cell candidate search runs twice per step instead of twice per iteration.
//
// The grid (GridView) and the list (NeighborListView) offer the same gather interface: sums of
// f(j) over i's fluid or boundary neighbours (sum_fluid, sum_boundary, and the 3-vector forms
// sum_fluid3, sum_boundary3), so the solver is written once for both. f must give 0 by itself for
// a j out of range, without a branch: the PCISPH gathers ran twice as fast with branch-free terms
// as with the same terms compiled into branches (docs/solver.md).
#pragma once
#include "algorithms/neighbor_grid.hpp"

MW_BACKEND_BEGIN

struct NeighborListView {
    const std::uint32_t* offsets = nullptr;         // [fluid_count + 1]
    const std::uint32_t* boundary_begin = nullptr;  // [fluid_count]: first boundary entry of i
    const std::uint32_t* indices = nullptr;

    template <class F>
    MW_INLINE Real sum_fluid(std::size_t i, Vec3, F&& f) const {
        return sum(offsets[i], boundary_begin[i], f);
    }
    template <class F>
    MW_INLINE Real sum_boundary(std::size_t i, Vec3, F&& f) const {
        return sum(boundary_begin[i], offsets[i + 1], f);
    }
    template <class F>
    MW_INLINE Vec3 sum_fluid3(std::size_t i, Vec3, F&& f) const {
        return sum3(offsets[i], boundary_begin[i], f);
    }
    template <class F>
    MW_INLINE Vec3 sum_boundary3(std::size_t i, Vec3, F&& f) const {
        return sum3(boundary_begin[i], offsets[i + 1], f);
    }

   private:
    template <class F>
    MW_INLINE Real sum(std::uint32_t begin, std::uint32_t end, F& f) const {
        Real total = 0;
        for (std::uint32_t k = begin; k < end; ++k) total += f(indices[k]);
        return total;
    }
    template <class F>
    MW_INLINE Vec3 sum3(std::uint32_t begin, std::uint32_t end, F& f) const {
        Vec3 total{0, 0, 0};
        for (std::uint32_t k = begin; k < end; ++k) total += f(indices[k]);
        return total;
    }
};

class NeighborList {
   public:
    // Lists for fluid particles [0, fluid_count) within `radius` of their current positions.
    inline void build(const GridView& grid, std::size_t fluid_count, View<const Vec3> position, Real radius);
    NeighborListView view() const {
        return NeighborListView{offsets_.view().data(), boundary_begin_.view().data(), indices_.view().data()};
    }
    std::size_t bytes() const { return counts_.bytes() + offsets_.bytes() + boundary_begin_.bytes() + indices_.bytes(); }
    std::size_t entries() const { return entries_; }

   private:
    DeviceArray<std::uint32_t> counts_, offsets_, boundary_begin_, indices_;
    std::size_t entries_ = 0;
};

inline void NeighborList::build(const GridView& grid, std::size_t fluid_count, View<const Vec3> position, Real radius) {
    const Real r2 = radius * radius;
    counts_.resize(fluid_count);
    boundary_begin_.resize(fluid_count);
    offsets_.resize(fluid_count + 1);
    View<std::uint32_t> counts = counts_.view(), boundary_begin = boundary_begin_.view();  // begin: fill pass
    parallel_for("neighbor_list_count", fluid_count, [=] MW_HD(std::size_t i) {
        const Vec3 xi = position[i];
        std::uint32_t count = 0;
        auto within = [&](std::uint32_t j) { count += norm2(xi - position[j]) < r2; };
        grid.for_each_fluid(xi, within);
        grid.for_each_static(xi, within);
        grid.for_each_solid(xi, within);
        counts[i] = count;
    });
    // One small host copy: the total sizes the index array (which only ever grows).
    entries_ = exclusive_scan("neighbor_list_offsets", counts_.cview(), View<std::uint32_t>{offsets_.view().data(), fluid_count});
    const std::uint32_t total = static_cast<std::uint32_t>(entries_);
    offsets_.upload_range(&total, fluid_count, 1);
    // Lists grow as a flow spreads along walls or compresses; a quarter of headroom keeps the
    // reallocation (and its first-touch page faults) out of almost every step.
    if (entries_ > indices_.capacity()) indices_.resize(entries_ + entries_ / 4 + 1);
    View<const std::uint32_t> offsets = offsets_.cview();
    std::uint32_t* indices = indices_.view().data();
    // Branch-free fill (whether a candidate is in range is unpredictable; with a branch the fill
    // took 2.7 times as long as the count pass, without one 1.6 times): every candidate is
    // written, the cursor advances only for those in range. Once i's row is full, writes go to a local dummy so that they never touch
    // the next particle's row, which another thread may be filling.
    parallel_for("neighbor_list_fill", fluid_count, [=] MW_HD(std::size_t i) {
        const Vec3 xi = position[i];
        const std::uint32_t row_end = offsets[i + 1];
        std::uint32_t k = offsets[i];
        std::uint32_t overflow = 0;
        auto add = [&](std::uint32_t j) {
            std::uint32_t* slot = k < row_end ? indices + k : &overflow;
            *slot = j;
            k += norm2(xi - position[j]) < r2;
        };
        grid.for_each_fluid(xi, add);
        boundary_begin[i] = k;
        grid.for_each_static(xi, add);
        grid.for_each_solid(xi, add);
    });
}

MW_BACKEND_END
