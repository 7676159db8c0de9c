// The OpenMP backend's primitives against plain sequential answers.
#include <doctest/doctest.h>

#include <algorithm>
#include <numeric>
#include <random>

#include "backend/backend.hpp"

using namespace mw;

TEST_CASE("reductions, scan and sort agree with sequential answers") {
    std::mt19937 rng(7);
    const std::size_t n = 100003;
    std::vector<int> values(n);
    for (auto& v : values) v = int(rng() % 1000) - 500;
    DeviceArray<int> data;
    data.upload(values);
    const View<const int> d = data.cview();
    CHECK(transform_reduce("sum", n, 0L, SumOp{}, [=](std::size_t i) { return long(d[i]); }) ==
          std::accumulate(values.begin(), values.end(), 0L));
    CHECK(transform_reduce("min", n, 1 << 30, MinOp{}, [=](std::size_t i) { return d[i]; }) ==
          *std::min_element(values.begin(), values.end()));
    CHECK(transform_reduce("max", n, -(1 << 30), MaxOp{}, [=](std::size_t i) { return d[i]; }) ==
          *std::max_element(values.begin(), values.end()));

    DeviceArray<int> scanned(n);
    const int total = exclusive_scan("scan", data.cview(), scanned.view());
    std::vector<int> expected(n);
    std::exclusive_scan(values.begin(), values.end(), expected.begin(), 0);
    CHECK(scanned.to_host() == expected);
    CHECK(total == std::accumulate(values.begin(), values.end(), 0));

    std::vector<std::uint32_t> keys(n), order(n);
    for (auto& k : keys) k = rng() % 5000;
    std::iota(order.begin(), order.end(), 0u);
    DeviceArray<std::uint32_t> k_in, k_out(n), v_in, v_out(n);
    k_in.upload(keys);
    v_in.upload(order);
    sort_pairs("sort", k_in.cview(), k_out.view(), v_in.cview(), v_out.view(), 13);
    std::vector<std::uint32_t> expected_order = order;
    std::stable_sort(expected_order.begin(), expected_order.end(),
                     [&](std::uint32_t a, std::uint32_t b) { return keys[a] < keys[b]; });
    CHECK(v_out.to_host() == expected_order);
}

TEST_CASE("memory ledger follows allocations") {
    const auto before = memory_ledger().current.load();
    {
        DeviceArray<double> big(1000);
        CHECK(memory_ledger().current.load() - before >= std::int64_t(8000));
    }
    CHECK(memory_ledger().current.load() == before);
}
