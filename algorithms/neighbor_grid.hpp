// Uniform-grid neighbour search with cell size h. Every step the moving particles are sorted by
// (group, cell) and the whole store is permuted, so neighbours sit next to each other in memory
// and a cell is a contiguous range. Static boundary particles are sorted once, into their own
// ranges. Loops gather over the 27 cells around a particle; there is no cap on neighbours.
//
// Groups order the moving range: fluid first, then boundary particles of moving solids (SBP,
// IBP), then particles no one gathers from (GPs, and particles that left the grid: "lost").
#pragma once
#include <cstdio>
#include <cmath>

#include "algorithms/particle_store.hpp"
#include "algorithms/particle_types.hpp"
#include "simulation/simulation.hpp"

MW_BACKEND_BEGIN

enum NeighborGroup : std::uint32_t { kGroupFluid = 0, kGroupSolid = 1, kGroupInactive = 2, kGroupCount = 3 };

MW_INLINE std::uint32_t neighbor_group(std::uint8_t type) {
    if (type == kFluid) return kGroupFluid;
    if (type == kSurfaceBoundary || type == kInnerBoundary) return kGroupSolid;
    return kGroupInactive;
}

// Interleaves the low 10 bits of v with two zero bits between each (for 3D Morton codes).
MW_INLINE std::uint32_t spread_bits_3(std::uint32_t v) {
    v &= 0x3ffu;
    v = (v | (v << 16)) & 0x030000ffu;
    v = (v | (v << 8)) & 0x0300f00fu;
    v = (v | (v << 4)) & 0x030c30c3u;
    v = (v | (v << 2)) & 0x09249249u;
    return v;
}

// The inverse of spread_bits_3: every third bit of v, from bit 0, packed into the low 10 bits.
MW_INLINE std::uint32_t compact_bits_3(std::uint32_t v) {
    v &= 0x09249249u;
    v = (v | (v >> 2)) & 0x030c30c3u;
    v = (v | (v >> 4)) & 0x0300f00fu;
    v = (v | (v >> 8)) & 0x030000ffu;
    v = (v | (v >> 16)) & 0x3ffu;
    return v;
}

struct GridShape {
    Vec3 origin{0, 0, 0};
    Real inv_cell = 1;
    int dims[3] = {1, 1, 1};
    std::uint32_t cell_count = 1;
    bool zorder = false;
    int morton_bits = 0;  // bits per axis in the Z-order key
    int reach = 1;        // cells per support radius: gathers visit (2 reach + 1)^3 cells

    // Cell coordinates of x; false when x is outside the grid (or not finite).
    MW_INLINE bool cell_of(Vec3 x, int c[3]) const {
        const Real f[3] = {(x.x - origin.x) * inv_cell, (x.y - origin.y) * inv_cell, (x.z - origin.z) * inv_cell};
        for (int a = 0; a < 3; ++a) {
            if (!(f[a] >= Real(0)) || !(f[a] < Real(dims[a]))) return false;
            c[a] = static_cast<int>(f[a]);
        }
        return true;
    }
    // Like cell_of, but clamps to the grid (for queries at predicted positions).
    MW_INLINE void clamped_cell_of(Vec3 x, int c[3]) const {
        const Real f[3] = {(x.x - origin.x) * inv_cell, (x.y - origin.y) * inv_cell, (x.z - origin.z) * inv_cell};
        for (int a = 0; a < 3; ++a) {
            int v = f[a] >= Real(0) ? static_cast<int>(f[a]) : 0;
            c[a] = v < dims[a] ? v : dims[a] - 1;
        }
    }
    // The cell coordinates a sort key (sort_key) was made from.
    MW_INLINE void cell_of_key(std::uint32_t key, int c[3]) const {
        if (zorder) {
            const std::uint32_t code = key & ((std::uint32_t(1) << (3 * morton_bits)) - 1u);
            for (int a = 0; a < 3; ++a) c[a] = static_cast<int>(compact_bits_3(code >> a));
        } else {
            const std::uint32_t cell = key % cell_count;
            c[0] = static_cast<int>(cell % std::uint32_t(dims[0]));
            c[1] = static_cast<int>((cell / std::uint32_t(dims[0])) % std::uint32_t(dims[1]));
            c[2] = static_cast<int>(cell / (std::uint32_t(dims[0]) * std::uint32_t(dims[1])));
        }
    }
    MW_INLINE std::uint32_t linear(const int c[3]) const {
        return (static_cast<std::uint32_t>(c[2]) * dims[1] + c[1]) * dims[0] + c[0];
    }
    // Sort key: group in the high part, then the cell in linear or Z-order.
    MW_INLINE std::uint32_t sort_key(std::uint32_t group, const int c[3]) const {
        if (zorder)
            return (group << (3 * morton_bits)) | (spread_bits_3(c[0]) | (spread_bits_3(c[1]) << 1) |
                                                   (spread_bits_3(c[2]) << 2));
        return group * cell_count + linear(c);
    }
    int key_bits() const {
        const std::uint64_t max_key = zorder ? (std::uint64_t(kGroupCount) << (3 * morton_bits))
                                             : std::uint64_t(kGroupCount) * cell_count;
        int bits = 1;
        while ((std::uint64_t(1) << bits) < max_key) ++bits;
        return bits;
    }
};

// What kernels need to gather neighbours; trivially copyable.
struct GridView {
    GridShape shape;
    const std::uint32_t* begin = nullptr;   // [group * cell_count + cell], moving groups 0 and 1
    const std::uint32_t* end = nullptr;
    const std::uint32_t* static_begin = nullptr;  // [cell]; null when the scene has no static boundary
    const std::uint32_t* static_end = nullptr;
    bool has_solids = false;  // moving solid particles exist: otherwise their 27 cells are skipped
    const std::uint32_t* sorted_key = nullptr;  // each moving particle's sort key at the last build

    // Calls f(j) for every particle j in the cells within one support radius of x's cell (27 cells
    // of size h, or 125 of size h/2), from the given cell ranges. The caller checks distances.
    template <class F>
    MW_INLINE void for_each_in_ranges(const std::uint32_t* first, const std::uint32_t* last, Vec3 x, F&& f) const {
        int c[3];
        shape.clamped_cell_of(x, c);
        for_each_in_ranges_around(first, last, c, f);
    }
    // The same around cell c.
    template <class F>
    MW_INLINE void for_each_in_ranges_around(const std::uint32_t* first, const std::uint32_t* last, const int c[3],
                                             F&& f) const {
        const int r = shape.reach;
        const int x0 = c[0] - r > 0 ? c[0] - r : 0;
        const int x1 = c[0] + r < shape.dims[0] ? c[0] + r : shape.dims[0] - 1;
        for (int dz = -r; dz <= r; ++dz) {
            const int z = c[2] + dz;
            if (z < 0 || z >= shape.dims[2]) continue;
            for (int dy = -r; dy <= r; ++dy) {
                const int y = c[1] + dy;
                if (y < 0 || y >= shape.dims[1]) continue;
                if (!shape.zorder) {
                    // Cells x0..x1 of a row are consecutive in the sort order: one merged range.
                    const std::uint32_t row = (static_cast<std::uint32_t>(z) * shape.dims[1] + y) * shape.dims[0];
                    std::uint32_t lo = 0xffffffffu, hi = 0;
                    for (int xc = x0; xc <= x1; ++xc) {
                        const std::uint32_t b = first[row + xc], e = last[row + xc];
                        if (b < e) {
                            lo = lo < b ? lo : b;
                            hi = e;
                        }
                    }
                    for (std::uint32_t j = lo; j < hi; ++j) f(j);
                } else {
                    for (int xc = x0; xc <= x1; ++xc) {
                        const int cc[3] = {xc, y, z};
                        const std::uint32_t cell = shape.linear(cc);
                        for (std::uint32_t j = first[cell], e = last[cell]; j < e; ++j) f(j);
                    }
                }
            }
        }
    }
    template <class F>
    MW_INLINE void for_each_fluid(Vec3 x, F&& f) const {
        for_each_in_ranges(begin, end, x, f);
    }
    template <class F>
    MW_INLINE void for_each_solid(Vec3 x, F&& f) const {
        if (has_solids) for_each_in_ranges(begin + shape.cell_count, end + shape.cell_count, x, f);
    }
    // Around the cell moving particle i was sorted into at this step's build (its position then),
    // however far it has moved since: a pair of moving particles is then visited from either
    // side or from neither (the velocity–position correction's two gathers, solid_contact.hpp).
    template <class F>
    MW_INLINE void for_each_fluid_around_particle(std::uint32_t i, F&& f) const {
        int c[3];
        shape.cell_of_key(sorted_key[i], c);
        for_each_in_ranges_around(begin, end, c, f);
    }
    template <class F>
    MW_INLINE void for_each_solid_around_particle(std::uint32_t i, F&& f) const {
        if (!has_solids) return;
        int c[3];
        shape.cell_of_key(sorted_key[i], c);
        for_each_in_ranges_around(begin + shape.cell_count, end + shape.cell_count, c, f);
    }
    // Whether for_each_solid_around_particle(i, ...) visits any particle.
    MW_INLINE bool has_solid_around_particle(std::uint32_t i) const {
        bool any = false;
        for_each_solid_around_particle(i, [&](std::uint32_t) { any = true; });
        return any;
    }
    template <class F>
    MW_INLINE void for_each_static(Vec3 x, F&& f) const {
        if (static_begin) for_each_in_ranges(static_begin, static_end, x, f);
    }
    // The gather interface shared with NeighborListView (the grid does not need i): sums of f(j)
    // over the 27 cells' fluid or boundary particles, of whatever type f returns (Real, Vec3).
    template <class F>
    MW_INLINE auto sum_fluid(std::size_t, Vec3 x, F&& f) const {
        decltype(f(0u)) sum{};
        for_each_fluid(x, [&](std::uint32_t j) { sum += f(j); });
        return sum;
    }
    template <class F>
    MW_INLINE auto sum_boundary(std::size_t, Vec3 x, F&& f) const {
        decltype(f(0u)) sum{};
        auto add = [&](std::uint32_t b) { sum += f(b); };
        for_each_static(x, add);
        for_each_solid(x, add);
        return sum;
    }
};

// Index ranges of the groups after a build (host-side).
struct GroupRanges {
    std::size_t fluid_end = 0;   // fluid: [0, fluid_end)
    std::size_t solid_end = 0;   // SBP/IBP: [fluid_end, solid_end); GPs and lost after
};

class NeighborGrid {
   public:
    explicit NeighborGrid(const DeviceContext& device) : device_(device) {}
    // Fits a grid of cells of size h / cells_per_h over [lo, hi].
    void configure(Vec3 lo, Vec3 hi, Real h, CellOrdering ordering, int cells_per_h = 1) {
        shape_.reach = cells_per_h;
        h = h / cells_per_h;
        shape_.origin = lo;
        shape_.inv_cell = Real(1) / h;
        // Cells per axis in double first: a domain 1e9 supports long would overflow an int.
        const Real extent[3] = {hi.x - lo.x, hi.y - lo.y, hi.z - lo.z};
        double dims[3], cells = 1;
        for (int a = 0; a < 3; ++a) cells *= dims[a] = std::max(1.0, double(std::ceil(extent[a] / h)));
        if (!(cells * kGroupCount < double(std::uint64_t(1) << 32))) {
            char count_text[32];
            std::snprintf(count_text, sizeof count_text, "%.3g", cells);
            throw InputError(std::string("the domain is too large for its support radius: ") + count_text +
                             " grid cells (at most about 1.4e9); shrink the domain or enlarge the support radius "
                             "(scene keys domain, fluid.support_radius)");
        }
        const std::uint64_t count = static_cast<std::uint64_t>(cells);
        int largest = 1;
        for (int a = 0; a < 3; ++a) {
            shape_.dims[a] = static_cast<int>(dims[a]);
            largest = std::max(largest, shape_.dims[a]);
        }
        shape_.cell_count = static_cast<std::uint32_t>(count);
        int bits = 0;
        while ((1 << bits) < largest) ++bits;
        // Z-order keys need 3 bits per level plus the group; beyond 1024 cells per axis, use linear.
        shape_.zorder = ordering == CellOrdering::kZOrder && bits <= 10;
        shape_.morton_bits = bits;
        end_.resize(2 * std::size_t(count));
        // Filled once: the linear-order gather reads the begin of empty cells too (then ignores
        // it), and a value never written would be a read of uninitialised memory to compute-sanitizer.
        begin_.assign(2 * std::size_t(count), 0);
    }
    const GridShape& shape() const { return shape_; }
    bool uses_zorder() const { return shape_.zorder; }

    // Sorts the static range once and records its cell ranges. Throws InputError if a static
    // particle lies outside the grid.
    inline void build_static(ParticleStore& store);
    // Sorts the moving range by (group, cell), permutes the store, fills the cell ranges.
    inline GroupRanges build(ParticleStore& store);

    GridView view() const {
        GridView v;
        v.shape = shape_;
        v.has_solids = has_solids_;
        v.begin = begin_.view().data();
        v.end = end_.view().data();
        v.sorted_key = sorted_keys_.view().data();
        if (!static_begin_.empty()) {
            v.static_begin = static_begin_.view().data();
            v.static_end = static_end_.view().data();
        }
        return v;
    }
    std::size_t bytes() const {
        return keys_.bytes() + sorted_keys_.bytes() + order_.bytes() + sorted_order_.bytes() + begin_.bytes() +
               end_.bytes() + static_begin_.bytes() + static_end_.bytes() + group_first_.bytes();
    }

   private:
    const DeviceContext& device_;
    GridShape shape_;
    bool has_solids_ = false;  // set by build(): the solid group is non-empty
    DeviceArray<std::uint32_t> keys_, sorted_keys_, order_, sorted_order_;
    DeviceArray<std::uint32_t> begin_, end_;               // moving groups 0 and 1
    DeviceArray<std::uint32_t> static_begin_, static_end_; // static boundary
    DeviceArray<std::uint32_t> group_first_;               // first index of each group after the sort
};


// The group and linear cell of a particle; particles outside the grid are inactive.
MW_INLINE void group_and_cell(const GridShape& shape, Vec3 x, std::uint8_t type, bool use_groups, std::uint32_t& group,
                              std::uint32_t& cell) {
    int c[3];
    group = use_groups ? neighbor_group(type) : kGroupFluid;
    cell = 0;
    if (!shape.cell_of(x, c))
        group = kGroupInactive;
    else
        cell = shape.linear(c);
}

// Fills `first`/`last` (indexed by group * cell_count + cell) from particles [0, n) already sorted
// by key; `offset` is added to the stored indices. Also records where each group starts.
inline void fill_cell_ranges(const DeviceContext& device, const GridShape& shape, View<const Vec3> position, View<const std::uint8_t> type,
                             bool use_groups, std::size_t n, std::size_t offset, std::uint32_t* first,
                             std::uint32_t* last, std::uint32_t* group_first) {
    const std::uint32_t cell_count = shape.cell_count;
    parallel_for(device, "grid_cell_ranges", n, [=] MW_HD(std::size_t i) {
        std::uint32_t g, cell;
        group_and_cell(shape, position[i], type[i], use_groups, g, cell);
        bool starts = i == 0, ends = i + 1 == n;
        if (!starts) {
            std::uint32_t pg, pcell;
            group_and_cell(shape, position[i - 1], type[i - 1], use_groups, pg, pcell);
            starts = pg != g || pcell != cell;
            if (pg != g && group_first) group_first[g] = static_cast<std::uint32_t>(i);
        } else if (group_first) {
            group_first[g] = 0;
        }
        if (!ends) {
            std::uint32_t ng, ncell;
            group_and_cell(shape, position[i + 1], type[i + 1], use_groups, ng, ncell);
            ends = ng != g || ncell != cell;
        }
        if (g == kGroupInactive) return;
        if (starts) first[g * cell_count + cell] = static_cast<std::uint32_t>(i + offset);
        if (ends) last[g * cell_count + cell] = static_cast<std::uint32_t>(i + 1 + offset);
    });
}

inline void NeighborGrid::build_static(ParticleStore& store) {
    const std::size_t n = store.static_count(), first = store.moving_count();
    if (n == 0) return;
    const GridShape shape = shape_;
    keys_.resize(n);
    order_.resize(n);
    sorted_keys_.resize(n);
    sorted_order_.resize(n);
    View<const Vec3> position{store.position.view().data() + first, n};
    View<std::uint32_t> keys = keys_.view(), order = order_.view();
    group_first_.assign(kGroupCount, 0);
    std::uint32_t* outside = group_first_.view().data();
    parallel_for(device_, "grid_static_keys", n, [=] MW_HD(std::size_t i) {
        int c[3] = {0, 0, 0};
        order[i] = static_cast<std::uint32_t>(i);
        if (shape.cell_of(position[i], c)) {
            keys[i] = shape.sort_key(kGroupFluid, c);
        } else {
            keys[i] = shape.sort_key(kGroupInactive, c);
            atomic_add(outside, 1u);
        }
    });
    std::uint32_t outside_count = 0;
    group_first_.download_range(&outside_count, 0, 1);
    if (outside_count)
        throw InputError(std::to_string(outside_count) +
                         " static boundary particles lie outside the simulation grid (move the static boxes "
                         "inside the domain)");
    sort_pairs(device_, "grid_static_sort", keys_.cview(), sorted_keys_.view(), order_.cview(), sorted_order_.view(),
               shape.key_bits());
    store.permute(sorted_order_.cview(), first);
    static_begin_.assign(shape.cell_count, 0);  // once per static build; see configure()
    static_end_.assign(shape.cell_count, 0);
    View<const std::uint8_t> type{store.type.view().data() + first, n};
    fill_cell_ranges(device_, shape, position, type, false, n, first, static_begin_.view().data(), static_end_.view().data(),
                     nullptr);
}

inline GroupRanges NeighborGrid::build(ParticleStore& store) {
    const std::size_t n = store.moving_count();
    GroupRanges ranges;
    if (n == 0) return ranges;
    const GridShape shape = shape_;
    keys_.resize(n);
    order_.resize(n);
    sorted_keys_.resize(n);
    sorted_order_.resize(n);
    View<const Vec3> position = store.position.cview();
    View<const std::uint8_t> type = store.type.cview();
    View<std::uint32_t> keys = keys_.view(), order = order_.view();
    parallel_for(device_, "grid_keys", n, [=] MW_HD(std::size_t i) {
        int c[3] = {0, 0, 0};
        std::uint32_t group = neighbor_group(type[i]);
        if (!shape.cell_of(position[i], c)) {
            group = kGroupInactive;
            c[0] = c[1] = c[2] = 0;
        }
        keys[i] = shape.sort_key(group, c);
        order[i] = static_cast<std::uint32_t>(i);
    });
    sort_pairs(device_, "grid_sort", keys_.cview(), sorted_keys_.view(), order_.cview(), sorted_order_.view(),
               shape.key_bits());
    store.permute(sorted_order_.cview(), 0);
    // Only the ends are cleared: an empty cell has end 0, so [begin, end) is empty whatever stale
    // begin it holds, and every non-empty cell gets both written below.
    end_.fill(0);
    group_first_.assign(kGroupCount, static_cast<std::uint32_t>(n));
    fill_cell_ranges(device_, shape, View<const Vec3>{position.data(), n}, View<const std::uint8_t>{type.data(), n}, true, n, 0,
                     begin_.view().data(), end_.view().data(), group_first_.view().data());
    std::uint32_t group_first[kGroupCount];
    group_first_.download_range(group_first, 0, kGroupCount);  // the one host copy of the build
    ranges.fluid_end = std::min(group_first[kGroupSolid], group_first[kGroupInactive]);
    if (group_first[kGroupFluid] != 0) ranges.fluid_end = 0;  // no fluid at all
    ranges.solid_end = group_first[kGroupInactive];
    if (ranges.solid_end < ranges.fluid_end) ranges.solid_end = ranges.fluid_end;
    has_solids_ = ranges.solid_end > ranges.fluid_end;
    return ranges;
}

MW_BACKEND_END
