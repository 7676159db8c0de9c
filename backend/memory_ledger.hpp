// Memory accounting per backend: bytes currently held by DeviceArrays and the peak. Each backend
// instantiates its own ledger inside its inline namespace.
#pragma once
#include <atomic>
#include <cstdint>

namespace mw {
struct MemoryLedger {
    std::atomic<std::int64_t> current{0};
    std::atomic<std::int64_t> peak{0};
    void add(std::int64_t bytes) {
        std::int64_t now = current.fetch_add(bytes) + bytes;
        std::int64_t seen = peak.load();
        while (now > seen && !peak.compare_exchange_weak(seen, now)) {
        }
    }
    void remove(std::int64_t bytes) { current.fetch_sub(bytes); }
};
}  // namespace mw
