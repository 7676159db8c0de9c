// The backend primitives against plain sequential answers, written once and compiled for each
// backend: tests/core (OpenMP) and tests/cuda_backend (CUDA, where a GPU is present).
#pragma once
#include <doctest/doctest.h>

#include <algorithm>
#include <numeric>
#include <random>
#include <vector>

#include "algorithms/pcisph.hpp"
#include "backend/backend.hpp"

namespace mw::test {

// A size that is no multiple of any block size, so partial blocks and tails are exercised.
constexpr std::size_t kPrimitiveCount = 100003;

inline std::vector<int> random_values(std::size_t n, unsigned seed) {
    std::mt19937 rng(seed);
    std::vector<int> values(n);
    for (auto& v : values) v = int(rng() % 1000) - 500;
    return values;
}

// Sizes from empty through one element and a single block (a reduction's one-tile path on a GPU,
// which the small scenes take) to many blocks with a partial tail.
constexpr std::size_t kReductionSizes[] = {0, 1, 7, 1000, kPrimitiveCount};

inline void check_reductions(const DeviceContext& device) {
    for (const std::size_t n : kReductionSizes) {
        CAPTURE(n);
        const std::vector<int> values = random_values(n, 7);
        DeviceArray<int> data;
        data.upload(values);
        const View<const int> d = data.cview();
        CHECK(transform_reduce(device, "sum", n, 0L, SumOp{}, [=] MW_HD(std::size_t i) { return long(d[i]); }) ==
              std::accumulate(values.begin(), values.end(), 0L));
        CHECK(transform_reduce(device, "min", n, 1 << 30, MinOp{}, [=] MW_HD(std::size_t i) { return d[i]; }) ==
              (n ? *std::min_element(values.begin(), values.end()) : 1 << 30));
        CHECK(transform_reduce(device, "max", n, -(1 << 30), MaxOp{}, [=] MW_HD(std::size_t i) { return d[i]; }) ==
              (n ? *std::max_element(values.begin(), values.end()) : -(1 << 30)));
    }
}

// The solver's own reductions over structs of mixed members (pcisph.hpp): the density error (a
// double sum and a Real maximum) and the motion summary (a double sum, a Real maximum and the
// lowest index of a bad value). Every member must come back, at every size.
inline void check_struct_reductions(const DeviceContext& device) {
    for (const std::size_t n : kReductionSizes) {
        CAPTURE(n);
        const std::vector<int> values = random_values(n, 19);
        DeviceArray<int> data;
        data.upload(values);
        const View<const int> d = data.cview();
        // Values of -500 and -499 are "bad"; the lowest such index must win.
        const MotionSummary motion =
            transform_reduce(device, "motion summary", n, MotionSummary{}, MotionSummaryOp{}, [=] MW_HD(std::size_t i) {
                const int v = d[i];
                return MotionSummary{0.5 * v, Real(v > 0 ? v : 0), v <= -499 ? static_cast<std::uint32_t>(i) : 0xffffffffu};
            });
        const DensityError density = transform_reduce(device, "density error", n, DensityError{}, DensityErrorOp{},
            [=] MW_HD(std::size_t i) { return DensityError{0.25 * d[i], Real(d[i] < 0 ? -d[i] : 0)}; });
        double sum = 0, quarter_sum = 0;
        Real max = 0, max_negative = 0;
        std::uint32_t first = 0xffffffffu;
        for (std::size_t i = 0; i < n; ++i) {
            sum += 0.5 * values[i];
            quarter_sum += 0.25 * values[i];
            max = std::max(max, Real(std::max(values[i], 0)));
            max_negative = std::max(max_negative, Real(std::max(-values[i], 0)));
            if (values[i] <= -499 && first == 0xffffffffu) first = static_cast<std::uint32_t>(i);
        }
        // Halves and quarters of integers: every partial sum is exact in double, in any order.
        CHECK(motion.kinetic_energy == sum);
        CHECK(motion.max_speed2 == max);
        CHECK(motion.first_bad == first);
        CHECK(density.sum == quarter_sum);
        CHECK(density.max == max_negative);
    }
}

// A scan and a reduction back to back, twice: on a GPU both return their result through the same
// small pinned host buffer.
inline void check_scan_then_reduce(const DeviceContext& device) {
    const std::vector<int> values = random_values(kPrimitiveCount, 23);
    DeviceArray<int> data, scanned(values.size());
    data.upload(values);
    const View<const int> d = data.cview();
    const int total = std::accumulate(values.begin(), values.end(), 0);
    const long total_long = std::accumulate(values.begin(), values.end(), 0L);
    for (int round = 0; round < 2; ++round) {
        CAPTURE(round);
        CHECK(exclusive_scan(device, "scan", data.cview(), scanned.view()) == total);
        CHECK(transform_reduce(device, "sum", values.size(), 0L, SumOp{}, [=] MW_HD(std::size_t i) { return long(d[i]); }) ==
              total_long);
    }
    std::vector<int> expected(values.size());
    std::exclusive_scan(values.begin(), values.end(), expected.begin(), 0);
    CHECK(scanned.to_host() == expected);
}

// Stage timers: a timed stage reads a positive time, a stage not started reads 0, and read() starts
// the next interval from 0 (the step's stats rely on all three).
inline void check_stage_timers(const DeviceContext& device) {
    const std::vector<int> values = random_values(kPrimitiveCount, 29);
    DeviceArray<int> data, out(values.size());
    data.upload(values);
    const View<const int> d = data.cview();
    const View<int> o = out.view();
    StageTimers timers(device, 2);
    timers.start(0);
    for (int pass = 0; pass < 20; ++pass)
        parallel_for(device, "timed work", values.size(), [=] MW_HD(std::size_t i) { o[i] = d[i] * 3 + pass; });
    timers.stop(0);
    double ms[2] = {-1, -1};
    timers.read(ms);
    CHECK(ms[0] > 0);
    CHECK(ms[0] < 10000);
    CHECK(ms[1] == 0);
    timers.read(ms);
    CHECK(ms[0] == 0);
    CHECK(ms[1] == 0);
    CHECK(out.to_host()[5] == values[5] * 3 + 19);  // the timed work was done
}

inline void check_exclusive_scan(const DeviceContext& device) {
    const std::vector<int> values = random_values(kPrimitiveCount, 11);
    DeviceArray<int> data, scanned(values.size());
    data.upload(values);
    const int total = exclusive_scan(device, "scan", data.cview(), scanned.view());
    std::vector<int> expected(values.size());
    std::exclusive_scan(values.begin(), values.end(), expected.begin(), 0);
    CHECK(scanned.to_host() == expected);
    CHECK(total == std::accumulate(values.begin(), values.end(), 0));
    // In place, as the neighbour lists scan their row sizes.
    const int total_in_place = exclusive_scan(device, "scan in place", data.cview(), data.view());
    CHECK(data.to_host() == expected);
    CHECK(total_in_place == total);
}

inline void check_sort_pairs(const DeviceContext& device) {
    const std::size_t n = kPrimitiveCount;
    std::mt19937 rng(13);
    std::vector<std::uint32_t> keys(n), order(n);
    for (auto& k : keys) k = rng() % 5000;
    std::iota(order.begin(), order.end(), 0u);
    DeviceArray<std::uint32_t> k_in, k_out(n), v_in, v_out(n);
    k_in.upload(keys);
    v_in.upload(order);
    sort_pairs(device, "sort", k_in.cview(), k_out.view(), v_in.cview(), v_out.view(), 13);
    // Radix sorts are stable: equal keys keep their input order, which the permutation relies on
    // for reproducible runs.
    std::vector<std::uint32_t> expected_order = order;
    std::stable_sort(expected_order.begin(), expected_order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
    CHECK(v_out.to_host() == expected_order);
    std::vector<std::uint32_t> sorted_keys = keys;
    std::sort(sorted_keys.begin(), sorted_keys.end());
    CHECK(k_out.to_host() == sorted_keys);

    // Bits above key_bits are ignored (as CUB does): random high bits leave the order unchanged.
    // 23 and 31 bits are the widths where the OpenMP sort's passes cover more bits than asked.
    for (int key_bits : {13, 23, 31}) {
        std::vector<std::uint32_t> noisy(n);
        for (std::size_t i = 0; i < n; ++i) noisy[i] = keys[i] | (std::uint32_t(rng()) << key_bits);
        k_in.upload(noisy);
        sort_pairs(device, "sort, noisy high bits", k_in.cview(), k_out.view(), v_in.cview(), v_out.view(), key_bits);
        CHECK_MESSAGE(v_out.to_host() == expected_order, "key_bits " << key_bits);
    }
}

inline void check_atomics(const DeviceContext& device) {
    // A histogram built by every index adding into a few bins at once.
    const std::vector<int> values = random_values(kPrimitiveCount, 17);
    const int bins = 7;
    DeviceArray<int> data, counts(bins);
    DeviceArray<float> sums(bins);
    data.upload(values);
    counts.fill(0);
    sums.fill(0.f);
    const View<const int> d = data.cview();
    const View<int> c = counts.view();
    const View<float> s = sums.view();
    parallel_for(device, "histogram", values.size(), [=] MW_HD(std::size_t i) {
        const int bin = (d[i] + 500) % bins;
        atomic_add(&c[bin], 1);
        atomic_add(&s[bin], 1.0f);  // whole numbers stay exact in float up to 2^24
    });
    std::vector<int> expected(bins, 0);
    for (int v : values) ++expected[(v + 500) % bins];
    CHECK(counts.to_host() == expected);
    const std::vector<float> float_sums = sums.to_host();
    for (int b = 0; b < bins; ++b) CHECK(float_sums[b] == float(expected[b]));
}

// A context's scratch grows with what its reductions and sorts needed, and belongs to it alone: a
// second context starts empty and leaves the first's as it was.
inline void check_context_scratch(const DeviceContext& device) {
    const std::vector<int> values = random_values(kPrimitiveCount, 31);
    DeviceArray<int> data;
    data.upload(values);
    const View<const int> d = data.cview();
    const long total = std::accumulate(values.begin(), values.end(), 0L);
    CHECK(transform_reduce(device, "sum", values.size(), 0L, SumOp{}, [=] MW_HD(std::size_t i) { return long(d[i]); }) ==
          total);
    const std::size_t held = device.scratch_bytes();
    CHECK(held > 0);
    {
        DeviceContext other;
        CHECK(other.scratch_bytes() == 0);
        CHECK(transform_reduce(other, "sum", 10, 0L, SumOp{}, [=] MW_HD(std::size_t i) { return long(d[i]); }) ==
              std::accumulate(values.begin(), values.begin() + 10, 0L));
        CHECK(device.scratch_bytes() == held);
    }
    CHECK(device.scratch_bytes() == held);
}

}  // namespace mw::test
