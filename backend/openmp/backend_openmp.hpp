// OpenMP backend: host memory, `omp parallel for`, deterministic chunked reductions and scans,
// a stable LSD radix sort. The API is the same, name for name, as backend/cuda/backend_cuda.cuh.
#pragma once
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstddef>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "backend/config.hpp"
#include "backend/device_array.hpp"
#include "common/errors.hpp"
#include "backend/reduce_ops.hpp"
#include "backend/view.hpp"

#define MW_BACKEND_BEGIN \
    namespace mw {       \
    inline namespace openmp_backend {
#define MW_BACKEND_END \
    }                  \
    }

MW_BACKEND_BEGIN

// Default for neighbors.lists "auto" (NeighborParams::Lists::kAuto): per-step neighbour lists beat re-gathering from the grid on CPU cores (measured).
constexpr bool kPrefersNeighborLists = true;

constexpr const char* kBackendName = "openmp";

bool backend_available();             // always true on the CPU
std::int64_t device_memory_free();    // physical memory available, bytes
// Creates OpenMP's thread team now, `threads` wide (0: OpenMP's default): libgomp ends the
// process when it cannot create the threads, and that had better happen before any output.
void start_thread_team(int threads);
// The width of the host's own parallel loops (sampling meshes, outside any simulation), and its
// team started at once; 0 keeps OpenMP's default.
void set_host_threads(int threads);

// Host memory, 64-byte aligned.
struct HostSpace {
    static void* allocate(std::size_t bytes) {
        void* p = std::aligned_alloc(64, ((bytes + 63) / 64) * 64);
        if (!p) throw DeviceError("out of host memory allocating " + std::to_string(bytes) + " bytes");
        return p;
    }
    static void release(void* p) { std::free(p); }
    static void to_device(void* dst, const void* src, std::size_t bytes) { std::memcpy(dst, src, bytes); }
    static void to_host(void* dst, const void* src, std::size_t bytes) { std::memcpy(dst, src, bytes); }
    static void within(void* dst, const void* src, std::size_t bytes) { std::memcpy(dst, src, bytes); }
    template <class T>
    static void fill(T* p, std::size_t n, T value) {
        const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(static)
        for (std::ptrdiff_t i = 0; i < count; ++i) p[i] = value;
    }
};

template <class T>
using DeviceArray = BasicDeviceArray<T, HostSpace>;

// Everything one simulation's launches share on the CPU: the thread count of its parallel
// regions, and the scratch its reductions, scans and sorts keep between calls (they grow, never
// shrink, so that a step allocates nothing once the first has run). A simulation owns one and
// passes it to every launch; two simulations in one process share nothing.
class DeviceContext {
   public:
    // `threads`: the width of every parallel region (0: OpenMP's default at construction).
    explicit DeviceContext(int threads = 0);
    DeviceContext(const DeviceContext&) = delete;
    DeviceContext& operator=(const DeviceContext&) = delete;

    int threads() const { return threads_; }
    std::string description() const;  // e.g. "2 OpenMP threads on Intel Xeon ..."
    // Makes this context's device current on the calling thread (nothing to do on the CPU).
    void activate() const {}
    void synchronize() const {}
    // Bytes held between calls: the sort's ping-pong buffers and the reductions' partials.
    std::size_t scratch_bytes() const;

    // At least `count` elements of T for a reduction's or scan's per-chunk partials.
    template <class T>
    T* partials(std::size_t count) const {
        const std::size_t words = (count * sizeof(T) + sizeof(Word) - 1) / sizeof(Word);
        if (partials_.size() < words) partials_.resize(words);
        return reinterpret_cast<T*>(partials_.data());
    }
    // The radix sort's buffers (backend_openmp.cpp).
    struct SortScratch {
        std::vector<std::uint32_t> keys, values;  // the ping-pong partner of the outputs
        std::vector<std::size_t> offsets;         // [thread][digit]: counts, then scatter positions
    };
    SortScratch& sort_scratch() const { return sort_; }

   private:
    using Word = std::max_align_t;
    int threads_ = 1;
    mutable std::vector<Word> partials_;
    mutable SortScratch sort_;
};

// f(i) for i in [0, n). `name` identifies the launch in errors and profiles.
template <class F>
void parallel_for(const DeviceContext& device, const char* /*name*/, std::size_t n, F f) {
    const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(static) num_threads(device.threads())
    for (std::ptrdiff_t i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
}

// Fixed chunking independent of the thread count keeps every reduction and scan bitwise
// reproducible from run to run and across --threads settings.
constexpr std::size_t kReduceChunk = 4096;

// op-reduction of f(i) over [0, n), starting from `identity`.
template <class T, class Op, class F>
T transform_reduce(const DeviceContext& device, const char* /*name*/, std::size_t n, T identity, Op op, F f) {
    const std::size_t chunks = (n + kReduceChunk - 1) / kReduceChunk;
    T* part = device.partials<T>(chunks);
    const std::ptrdiff_t chunk_count = static_cast<std::ptrdiff_t>(chunks);
#pragma omp parallel for schedule(static) num_threads(device.threads())
    for (std::ptrdiff_t c = 0; c < chunk_count; ++c) {
        T acc = identity;
        const std::size_t begin = static_cast<std::size_t>(c) * kReduceChunk;
        const std::size_t end = std::min(n, begin + kReduceChunk);
        for (std::size_t i = begin; i < end; ++i) acc = op(acc, f(i));
        part[c] = acc;
    }
    T total = identity;
    for (std::size_t c = 0; c < chunks; ++c) total = op(total, part[c]);
    return total;
}

// out[i] = in[0] + ... + in[i-1]; returns the total. `out` may alias `in`.
template <class T>
T exclusive_scan(const DeviceContext& device, const char* /*name*/, View<const T> in, View<T> out) {
    const std::size_t n = in.size();
    const std::size_t chunks = (n + kReduceChunk - 1) / kReduceChunk;
    T* part = device.partials<T>(chunks + 1);
    const std::ptrdiff_t chunk_count = static_cast<std::ptrdiff_t>(chunks);
#pragma omp parallel for schedule(static) num_threads(device.threads())
    for (std::ptrdiff_t c = 0; c < chunk_count; ++c) {
        T acc = T(0);
        const std::size_t begin = static_cast<std::size_t>(c) * kReduceChunk;
        const std::size_t end = std::min(n, begin + kReduceChunk);
        for (std::size_t i = begin; i < end; ++i) acc += in[i];
        part[c] = acc;
    }
    T running = T(0);
    for (std::size_t c = 0; c < chunks; ++c) {
        T chunk_sum = part[c];
        part[c] = running;
        running += chunk_sum;
    }
#pragma omp parallel for schedule(static) num_threads(device.threads())
    for (std::ptrdiff_t c = 0; c < chunk_count; ++c) {
        T acc = part[c];
        const std::size_t begin = static_cast<std::size_t>(c) * kReduceChunk;
        const std::size_t end = std::min(n, begin + kReduceChunk);
        for (std::size_t i = begin; i < end; ++i) {
            T value = in[i];
            out[i] = acc;
            acc += value;
        }
    }
    return running;
}

// Sorts (key, value) pairs by key, stably (equal keys keep their input order), looking only at the
// low `key_bits` bits of the keys, like the GPU radix sort. A parallel LSD radix sort whose output
// does not depend on the thread count; its scratch is the context's. The outputs must not alias
// the inputs (CUB's sort requires the same).
void sort_pairs(const DeviceContext& device, const char* name, View<const std::uint32_t> keys_in,
                View<std::uint32_t> keys_out, View<const std::uint32_t> values_in, View<std::uint32_t> values_out,
                int key_bits);

MW_INLINE void atomic_add(int* address, int value) { __atomic_fetch_add(address, value, __ATOMIC_RELAXED); }
MW_INLINE void atomic_add(unsigned* address, unsigned value) {
    __atomic_fetch_add(address, value, __ATOMIC_RELAXED);
}
MW_INLINE void atomic_add(float* address, float value) {
#pragma omp atomic
    *address += value;
}
MW_INLINE void atomic_add(double* address, double value) {
#pragma omp atomic
    *address += value;
}

// Per-stage wall-clock timers. A stage is started and stopped at most once per step; read()
// returns each stage's milliseconds for the step and clears them.
class StageTimers {
   public:
    StageTimers(const DeviceContext& /*device*/, int stage_count) : start_(stage_count), elapsed_ms_(stage_count, 0.0) {}
    void start(int stage) { start_[stage] = std::chrono::steady_clock::now(); }
    void stop(int stage) {
        elapsed_ms_[stage] +=
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_[stage]).count();
    }
    void read(double* ms_out) {
        for (std::size_t s = 0; s < elapsed_ms_.size(); ++s) {
            ms_out[s] = elapsed_ms_[s];
            elapsed_ms_[s] = 0.0;
        }
    }

   private:
    std::vector<std::chrono::steady_clock::time_point> start_;
    std::vector<double> elapsed_ms_;
};

MW_BACKEND_END
