// Non-template parts of the OpenMP backend.
#include <unistd.h>

#include <fstream>

#define MW_BACKEND_OPENMP
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

void set_threads(int threads) {
    if (threads > 0) omp_set_num_threads(threads);
}

int thread_count() { return omp_get_max_threads(); }

bool backend_available() { return true; }

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

std::string device_description() {
    return std::to_string(thread_count()) + " OpenMP threads on " + cpu_model();
}

std::int64_t device_memory_free() {
    const long pages = sysconf(_SC_AVPHYS_PAGES);
    const long page_size = sysconf(_SC_PAGE_SIZE);
    return static_cast<std::int64_t>(pages) * page_size;
}

void sort_pairs(const char* /*name*/, View<const std::uint32_t> keys_in, View<std::uint32_t> keys_out,
                View<const std::uint32_t> values_in, View<std::uint32_t> values_out, int /*key_bits*/) {
    const std::size_t n = keys_in.size();
    static thread_local std::vector<std::uint64_t> packed;  // grows only; no per-step allocation
    if (packed.size() < n) packed.resize(n);
    std::uint64_t* words = packed.data();
    const std::ptrdiff_t count = static_cast<std::ptrdiff_t>(n);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < count; ++i)
        words[i] = (static_cast<std::uint64_t>(keys_in[i]) << 32) | values_in[i];
    __gnu_parallel::sort(words, words + n);
#pragma omp parallel for schedule(static)
    for (std::ptrdiff_t i = 0; i < count; ++i) {
        keys_out[i] = static_cast<std::uint32_t>(words[i] >> 32);
        values_out[i] = static_cast<std::uint32_t>(words[i] & 0xffffffffu);
    }
}

MW_BACKEND_END
