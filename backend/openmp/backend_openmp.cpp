// Non-template parts of the OpenMP backend.
#include <unistd.h>

#include <fstream>

#define MW_BACKEND_OPENMP
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

void start_thread_team(int threads) {
    // An empty region would be dropped by the compiler, hence the call inside.
    int team = 0;
    const int width = threads > 0 ? threads : omp_get_max_threads();
#pragma omp parallel num_threads(width)
    {
#pragma omp single
        team = omp_get_num_threads();
    }
    (void)team;
}

void set_host_threads(int threads) {
    if (threads > 0) omp_set_num_threads(threads);
    start_thread_team(threads);
}

bool backend_available() { return true; }

DeviceContext::DeviceContext(int threads) : threads_(threads > 0 ? threads : omp_get_max_threads()) {}

static std::string cpu_model() {
    std::ifstream cpuinfo("/proc/cpuinfo");
    std::string line;
    while (std::getline(cpuinfo, line)) {
        if (line.rfind("model name", 0) == 0) {
            auto colon = line.find(':');
            if (colon != std::string::npos) return line.substr(colon + 2);
        }
    }
    return "unknown CPU";
}

std::string DeviceContext::description() const {
    return std::to_string(threads_) + (threads_ == 1 ? " OpenMP thread on " : " OpenMP threads on ") + cpu_model();
}

std::int64_t device_memory_free() {
    const long pages = sysconf(_SC_AVPHYS_PAGES);
    const long page_size = sysconf(_SC_PAGE_SIZE);
    return static_cast<std::int64_t>(pages) * page_size;
}

// Stable LSD radix sort of (key, value) pairs on the low `key_bits` bits of the keys, as CUB's
// DeviceRadixSort::SortPairs does on the GPU. Hand-written, against the project's preference for
// libraries, because the ones at hand fall short here: GNU's parallel mergesort allocates n-sized
// temporaries on every call, and TBB's parallel_sort runs on its own thread pool, outside OpenMP
// and --threads. Called every step by the neighbour grid, so:
//  * Scratch is the context's and only grows: same-size or smaller calls allocate nothing.
//  * Stability is by input position (never by value), and each thread owns a fixed contiguous
//    chunk whose elements keep their order within every bucket, so the output is the one stable
//    order whatever the thread count; runs stay bitwise reproducible.
//  * Only as many passes as key_bits needs, each at most 11 bits wide (a 2048-entry histogram per
//    thread stays in L1/L2), split evenly: 24 bits -> 3 passes of 8, 31 bits -> 3 passes of 11.
std::size_t DeviceContext::scratch_bytes() const {
    return (sort_.keys.capacity() + sort_.values.capacity()) * sizeof(std::uint32_t) +
           sort_.offsets.capacity() * sizeof(std::size_t) + partials_.capacity() * sizeof(Word);
}

void sort_pairs(const DeviceContext& device, const char* /*name*/, View<const std::uint32_t> keys_in,
                View<std::uint32_t> keys_out, View<const std::uint32_t> values_in, View<std::uint32_t> values_out,
                int key_bits) {
    const std::size_t n = keys_in.size();
    if (n == 0) return;
    constexpr int kMaxDigitBits = 11;
    const int bits = std::clamp(key_bits, 1, 32);
    const int passes = (bits + kMaxDigitBits - 1) / kMaxDigitBits;
    const int digit_bits = (bits + passes - 1) / passes;
    const std::size_t radix = std::size_t(1) << digit_bits;
    // Small inputs sort on one thread, where fork/join and barriers would dominate (threshold
    // not tuned); the result is the same for any thread count.
    constexpr std::size_t kParallelMin = 1 << 14;
    const int max_threads = n < kParallelMin ? 1 : device.threads();

    DeviceContext::SortScratch& scratch = device.sort_scratch();
    if (scratch.keys.size() < n) {
        scratch.keys.resize(n);
        scratch.values.resize(n);
    }
    if (scratch.offsets.size() < max_threads * radix) scratch.offsets.resize(max_threads * radix);
    std::size_t* const offsets = scratch.offsets.data();

    // Pass p writes keys_out when (passes - 1 - p) is even, so the last pass lands in the output.
    std::uint32_t* const key_buf[2] = {keys_out.data(), scratch.keys.data()};
    std::uint32_t* const value_buf[2] = {values_out.data(), scratch.values.data()};

#pragma omp parallel num_threads(max_threads)
    {
        // The team may be smaller than asked for; chunks follow the actual size.
        const std::size_t threads = static_cast<std::size_t>(omp_get_num_threads());
        const std::size_t t = static_cast<std::size_t>(omp_get_thread_num());
        const std::size_t begin = n * t / threads, end = n * (t + 1) / threads;
        std::size_t* const mine = offsets + t * radix;
        const std::uint32_t* src_keys = keys_in.data();
        const std::uint32_t* src_values = values_in.data();
        for (int pass = 0; pass < passes; ++pass) {
            const int shift = pass * digit_bits;
            // The last pass may be narrower: bits above key_bits are ignored, as CUB does.
            const int width = std::min(digit_bits, bits - shift);
            const std::uint32_t mask = static_cast<std::uint32_t>((std::uint64_t(1) << width) - 1);
            std::uint32_t* const dst_keys = key_buf[(passes - 1 - pass) & 1];
            std::uint32_t* const dst_values = value_buf[(passes - 1 - pass) & 1];
            std::fill(mine, mine + radix, std::size_t(0));
            for (std::size_t i = begin; i < end; ++i) ++mine[(src_keys[i] >> shift) & mask];
#pragma omp barrier
            // Exclusive scan in (digit, thread) order: thread t's run of digit d follows every
            // smaller digit and the runs of d from lower-numbered (earlier) chunks.
#pragma omp single
            {
                std::size_t running = 0;
                for (std::size_t d = 0; d < radix; ++d)
                    for (std::size_t u = 0; u < threads; ++u) {
                        const std::size_t count = offsets[u * radix + d];
                        offsets[u * radix + d] = running;
                        running += count;
                    }
            }  // implicit barrier: every thread sees the scanned offsets
            for (std::size_t i = begin; i < end; ++i) {
                const std::uint32_t key = src_keys[i];
                const std::size_t at = mine[(key >> shift) & mask]++;
                dst_keys[at] = key;
                dst_values[at] = src_values[i];
            }
#pragma omp barrier  // the pass's output is complete before anyone reads it or reuses offsets
            src_keys = dst_keys;
            src_values = dst_values;
        }
    }
}

MW_BACKEND_END
