// OpenMP backend: host memory, `omp parallel for`, deterministic chunked reductions and scans,
// a stable LSD radix sort. The API is the same, name for name, as backend/cuda/backend_cuda.cuh.
#pragma once
#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <string>
#include <utility>
#include <vector>

#include "backend/config.hpp"
#include "backend/device_array.hpp"
#include "backend/errors.hpp"
#include "backend/memory_ledger.hpp"
#include "backend/reduce_ops.hpp"
#include "backend/view.hpp"

#define MW_BACKEND_BEGIN \
    namespace mw {       \
    inline namespace openmp_backend {
#define MW_BACKEND_END \
    }                  \
    }

MW_BACKEND_BEGIN

// Default for SimulationParams::neighbor_lists = kAuto: per-step neighbour lists beat re-gathering from the grid on CPU cores (measured).
constexpr bool kPrefersNeighborLists = true;

constexpr const char* kBackendName = "openmp";

inline MemoryLedger& memory_ledger() {
    static MemoryLedger ledger;
    return ledger;
}

void set_threads(int threads);        // 0 keeps the OpenMP default
void start_thread_team();             // creates the threads now (libgomp exits if it cannot)
int thread_count();
bool backend_available();             // always true on the CPU
std::string device_description();     // e.g. "2 OpenMP threads on Intel Xeon ..."
std::int64_t device_memory_free();    // physical memory available, bytes
inline void synchronize() {}

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
    static MemoryLedger& ledger() { return memory_ledger(); }
};

template <class T>
using DeviceArray = BasicDeviceArray<T, HostSpace>;

// f(i) for i in [0, n). `name` identifies the launch in errors and profiles.
template <class F>
void parallel_for(const char* /*name*/, std::size_t n, F f) {
    const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < count; ++i) f(static_cast<std::size_t>(i));
}

// Fixed chunking independent of the thread count keeps every reduction and scan bitwise
// reproducible from run to run and across --threads settings.
constexpr std::size_t kReduceChunk = 4096;

template <class T>
std::vector<T>& reduction_workspace() {
    static thread_local std::vector<T> partials;
    return partials;
}

// op-reduction of f(i) over [0, n), starting from `identity`.
template <class T, class Op, class F>
T transform_reduce(const char* /*name*/, std::size_t n, T identity, Op op, F f) {
    const std::size_t chunks = (n + kReduceChunk - 1) / kReduceChunk;
    std::vector<T>& partials = reduction_workspace<T>();
    if (partials.size() < chunks) partials.resize(chunks);
    T* part = partials.data();
    const std::ptrdiff_t chunk_count = static_cast<std::ptrdiff_t>(chunks);
#pragma omp parallel for schedule(static)
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
T exclusive_scan(const char* /*name*/, View<const T> in, View<T> out) {
    const std::size_t n = in.size();
    const std::size_t chunks = (n + kReduceChunk - 1) / kReduceChunk;
    std::vector<T>& partials = reduction_workspace<T>();
    if (partials.size() < chunks + 1) partials.resize(chunks + 1);
    T* part = partials.data();
    const std::ptrdiff_t chunk_count = static_cast<std::ptrdiff_t>(chunks);
#pragma omp parallel for schedule(static)
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
#pragma omp parallel for schedule(static)
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
// does not depend on the thread count; its scratch persists across calls (see the .cpp). The
// outputs must not alias the inputs (CUB's sort requires the same).
void sort_pairs(const char* name, View<const std::uint32_t> keys_in, View<std::uint32_t> keys_out,
                View<const std::uint32_t> values_in, View<std::uint32_t> values_out, int key_bits);

// Scratch the backend keeps between calls and that no DeviceArray owner counts: the sort's
// ping-pong buffers (8 bytes per sorted item) of the calling thread. Grows while a simulation
// lives; release_backend_scratch (called when the last one goes, backend/scratch_user.hpp) frees
// the calling thread's.
std::size_t backend_scratch_bytes();
void release_backend_scratch();

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
    explicit StageTimers(int stage_count) : start_(stage_count), elapsed_ms_(stage_count, 0.0) {}
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
