// Per-step neighbour lists for fluid particles (CSR with slack): every fluid and boundary particle
// within h of fluid particle i at the start of the step, fluid neighbours first. Built once per
// step from the grid, then read by every PCISPH iteration.
//
// One candidate search per step, not two: each row gets room for the particle's count of the
// last step (a persistent store field, so it travels with the particle through the sort) plus
// kRowSlack; one fill pass writes the rows and records the exact counts. If any row overflowed
// (rare: a count grew by more than the slack in one step), the rows are laid out again from the
// exact counts and filled a second time. Exact either way: no cap, nothing dropped.
//
// The grid (GridView) and the list (NeighborListView) offer the same gather interface: sums of
// f(j) over i's fluid or boundary neighbours (sum_fluid, sum_boundary; the sum has the type f
// returns), so the solver is written once for both. f must give 0 by itself for
// a j out of range, without a branch: the PCISPH gathers ran twice as fast with branch-free terms
// as with the same terms compiled into branches (docs/solver.md).
#pragma once
#include <string>

#include "algorithms/neighbor_grid.hpp"
#include "common/errors.hpp"

MW_BACKEND_BEGIN

struct NeighborListView {
    const std::uint32_t* offsets = nullptr;         // [fluid_count + 1]: first slot of each row
    const std::uint32_t* boundary_begin = nullptr;  // [fluid_count]: first boundary entry of i
    const std::uint32_t* counts = nullptr;          // [fluid_count]: entries in i's row
    const std::uint32_t* indices = nullptr;

    MW_INLINE std::uint32_t row_end(std::size_t i) const { return offsets[i] + counts[i]; }
    template <class F>
    MW_INLINE auto sum_fluid(std::size_t i, Vec3, F&& f) const {
        return sum(offsets[i], boundary_begin[i], f);
    }
    template <class F>
    MW_INLINE auto sum_boundary(std::size_t i, Vec3, F&& f) const {
        return sum(boundary_begin[i], row_end(i), f);
    }

   private:
    template <class F>
    MW_INLINE auto sum(std::uint32_t begin, std::uint32_t end, F& f) const {
        decltype(f(0u)) total{};
        for (std::uint32_t k = begin; k < end; ++k) total += f(indices[k]);
        return total;
    }
};

// What one fill found, summed over the rows: rows that overflowed their slots, and the slots the
// next layout will take (the exact counts plus slack), in 64 bits: the row offsets are 32-bit.
struct ListFillSummary {
    std::uint64_t overflowed_rows = 0;
    std::uint64_t next_layout_slots = 0;
    MW_INLINE ListFillSummary operator+(const ListFillSummary& o) const {
        return {overflowed_rows + o.overflowed_rows, next_layout_slots + o.next_layout_slots};
    }
};

class NeighborList {
   public:
    // Room per row beyond the last step's count: 64 bytes per fluid particle. A particle moving
    // toward a wall sampled at r0/2 gains many boundary neighbours in one step. Steps that needed
    // a second fill (measured): slack 4: 643 of 1000 (6,859-particle block), 152 of 250 (59,319),
    // 1169 of 1209 (default dam break, CFL steps); slack 8: 3, 4, 439; slack 16: 1, 1, 27.
    static constexpr std::uint32_t kRowSlack = 16;

    explicit NeighborList(const DeviceContext& device) : device_(device) {}

    // Lists for fluid particles [0, fluid_count) within `radius` of their current positions.
    // row_counts[i] is i's count from the last build (0 before the first) and receives the new
    // one; the lists read it, so it must stay alive and unsorted until the next build.
    inline void build(const GridView& grid, std::size_t fluid_count, View<const Vec3> position, Real radius,
                      View<std::uint32_t> row_counts);
    // Room for up to `fluid_capacity` rows as long as the last build's on average, made once at
    // set-up, so that fluid arriving at run time (emitters, melting) does not reallocate the
    // lists in the step loop. Growing a buffer drops the rows built so far: the next build lays
    // them out again.
    void reserve(std::size_t fluid_capacity) {
        const double per_row = last_fluid_count_ > 0 && last_fluid_count_ != std::size_t(-1)
                                   ? double(next_layout_slots_) / double(last_fluid_count_)
                                   : double(4 * kRowSlack);
        const std::size_t rows = offsets_.size() > 0 ? offsets_.size() - 1 : 0, bounds = boundary_begin_.size();
        offsets_.resize(fluid_capacity + 1);
        boundary_begin_.resize(fluid_capacity);
        offsets_.resize(rows + 1);  // the sizes back; the capacity stays
        boundary_begin_.resize(bounds);
        const auto slots = static_cast<std::uint64_t>(per_row * 1.25 * double(fluid_capacity)) + 1;
        check_slots(slots);
        if (slots > indices_.capacity()) {
            const std::size_t used = indices_.size();
            indices_.resize(slots);
            indices_.resize(used);
        }
    }
    NeighborListView view() const {
        return NeighborListView{offsets_.view().data(), boundary_begin_.view().data(), row_counts_,
                                indices_.view().data()};
    }
    std::size_t bytes() const { return offsets_.bytes() + boundary_begin_.bytes() + indices_.bytes(); }
    long second_fills() const { return second_fills_; }  // builds that needed a second fill

    // Offsets and slots are 32-bit (half the memory of 64-bit ones, and the lists already take
    // most of a fluid particle's bytes); a layout past that limit is refused, never wrapped.
    static void check_slots(std::uint64_t slots) {
        if (slots > 0xffffffffull)
            throw DeviceError("the neighbour lists would need " + std::to_string(slots) +
                              " slots, more than their 32-bit offsets address (4294967295); run with "
                              "--set neighbors.lists=off (grid gathers, no lists)");
    }

    // The two steps of build(). Public only because nvcc allows no device lambda inside a
    // private member function.
    // Rows of row_counts[i] + kRowSlack slots. One small host copy (the total, to size indices).
    inline void lay_out_rows(std::size_t fluid_count, View<const std::uint32_t> row_counts);
    // Fills every row and records the exact counts.
    inline ListFillSummary fill(const GridView& grid, std::size_t fluid_count, View<const Vec3> position,
                                Real radius, View<std::uint32_t> row_counts);

   private:
    const DeviceContext& device_;
    DeviceArray<std::uint32_t> offsets_, boundary_begin_, indices_;
    const std::uint32_t* row_counts_ = nullptr;
    long second_fills_ = 0;
    // Slots of the next layout, known from the last fill when the fluid count has not changed
    // since; otherwise (the first build) summed once more from the counts.
    std::uint64_t next_layout_slots_ = 0;
    std::size_t last_fluid_count_ = std::size_t(-1);
};

inline void NeighborList::lay_out_rows(std::size_t fluid_count, View<const std::uint32_t> row_counts) {
    offsets_.resize(fluid_count + 1);
    // Row sizes, and a 0 after the last, so that the in-place scan leaves the total in
    // offsets[fluid_count] without an upload.
    View<std::uint32_t> offsets = offsets_.view();
    parallel_for(device_, "neighbor_list_row_sizes", fluid_count + 1, [=] MW_HD(std::size_t i) {
        offsets[i] = i < fluid_count ? row_counts[i] + kRowSlack : 0u;
    });
    const std::size_t total = exclusive_scan(device_, "neighbor_list_offsets", offsets_.cview(), offsets);
    // Lists grow as a flow spreads along walls or compresses; a quarter of headroom keeps the
    // reallocation (and its first-touch page faults) out of almost every step.
    if (total > indices_.capacity()) indices_.resize(total + total / 4 + 1);
}

inline ListFillSummary NeighborList::fill(const GridView& grid, std::size_t fluid_count, View<const Vec3> position,
                                      Real radius, View<std::uint32_t> row_counts) {
    const Real r2 = radius * radius;
    boundary_begin_.resize(fluid_count);
    View<const std::uint32_t> offsets = offsets_.cview();
    View<std::uint32_t> boundary_begin = boundary_begin_.view();
    std::uint32_t* indices = indices_.view().data();
    // Branch-free fill (whether a candidate is in range is unpredictable; with a branch the fill
    // took 2.7 times as long as a counting pass, without one 1.6 times): every candidate is
    // written, the cursor advances only for those in range. Past the row's last slot, writes go
    // to a local dummy, so they never touch the next row, which another thread may be filling.
    parallel_for(device_, "neighbor_list_fill", fluid_count, [=] MW_HD(std::size_t i) {
        const Vec3 xi = position[i];
        const std::uint32_t first = offsets[i], last = offsets[i + 1];
        std::uint32_t k = first;
        std::uint32_t dummy = 0;
        auto add = [&](std::uint32_t j) {
            std::uint32_t* slot = k < last ? indices + k : &dummy;
            *slot = j;
            k += norm2(xi - position[j]) < r2;
        };
        grid.for_each_fluid(xi, add);
        boundary_begin[i] = k;
        grid.for_each_static(xi, add);
        grid.for_each_solid(xi, add);
        row_counts[i] = k - first;
    });
    View<const std::uint32_t> counts = row_counts;
    return transform_reduce(device_, "neighbor_list_overflow", fluid_count, ListFillSummary{}, SumOp{},
                            [=] MW_HD(std::size_t i) {
                                return ListFillSummary{std::uint64_t(offsets[i] + counts[i] > offsets[i + 1]),
                                                       std::uint64_t(counts[i]) + kRowSlack};
                            });
}

inline void NeighborList::build(const GridView& grid, std::size_t fluid_count, View<const Vec3> position, Real radius,
                                View<std::uint32_t> row_counts) {
    row_counts_ = row_counts.data();
    if (fluid_count != last_fluid_count_) {
        View<const std::uint32_t> counts = row_counts;
        next_layout_slots_ = transform_reduce(device_, "neighbor_list_slots", fluid_count, std::uint64_t(0), SumOp{},
                                              [=] MW_HD(std::size_t i) { return std::uint64_t(counts[i]) + kRowSlack; });
        last_fluid_count_ = fluid_count;
    }
    check_slots(next_layout_slots_);
    lay_out_rows(fluid_count, row_counts);
    ListFillSummary filled = fill(grid, fluid_count, position, radius, row_counts);
    next_layout_slots_ = filled.next_layout_slots;
    if (filled.overflowed_rows == 0) return;
    // Some row overflowed: row_counts now holds every exact count, so the second fill fits.
    ++second_fills_;
    check_slots(next_layout_slots_);
    lay_out_rows(fluid_count, row_counts);
    filled = fill(grid, fluid_count, position, radius, row_counts);
    next_layout_slots_ = filled.next_layout_slots;
}

MW_BACKEND_END
