// Non-template parts of the CUDA backend.
#include <cstdlib>

#define MW_BACKEND_CUDA
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

void set_threads(int) {}
int thread_count() { return 1; }

void check_cuda(cudaError_t status, const char* what) {
    if (status != cudaSuccess) {
        (void)cudaGetLastError();
        throw DeviceError(std::string("CUDA error in ") + what + ": " + cudaGetErrorString(status));
    }
}

bool debug_sync_enabled() {
    static const bool enabled = [] {
        const char* flag = std::getenv("MELTWATER_CUDA_SYNC");
        return flag && flag[0] == '1';
    }();
    return enabled;
}

void check_launch(const char* name) {
    check_cuda(cudaGetLastError(), name);
    if (debug_sync_enabled()) check_cuda(cudaDeviceSynchronize(), name);
}

bool backend_available() { return unavailable_reason().empty(); }

std::string unavailable_reason() {
    int count = 0;
    const cudaError_t status = cudaGetDeviceCount(&count);
    if (status == cudaSuccess) return count > 0 ? std::string() : std::string("no CUDA device found");
    (void)cudaGetLastError();
    // The runtime reports a machine with no driver at all as an insufficient driver.
    if (status == cudaErrorInsufficientDriver)
        return "no CUDA driver, or one older than this build's CUDA runtime (cudaErrorInsufficientDriver)";
    if (status == cudaErrorNoDevice) return "no CUDA device found";
    return std::string("no usable CUDA device: ") + cudaGetErrorString(status) + " (" + cudaGetErrorName(status) + ")";
}

std::string device_description() {
    if (!backend_available()) return "no CUDA device";
    int device = 0;
    cudaGetDevice(&device);
    cudaDeviceProp prop{};
    cudaGetDeviceProperties(&prop, device);
    char text[256];
    std::snprintf(text, sizeof text, "%s (sm_%d%d, %.1f GiB)", prop.name, prop.major, prop.minor,
                  static_cast<double>(prop.totalGlobalMem) / (1024.0 * 1024.0 * 1024.0));
    return text;
}

std::int64_t device_memory_free() {
    std::size_t free_bytes = 0, total_bytes = 0;
    if (cudaMemGetInfo(&free_bytes, &total_bytes) != cudaSuccess) {
        (void)cudaGetLastError();
        return 0;
    }
    return static_cast<std::int64_t>(free_bytes);
}

int multiprocessor_count() {
    static const int count = [] {
        int device = 0, sms = 0;
        if (cudaGetDevice(&device) != cudaSuccess ||
            cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device) != cudaSuccess) {
            (void)cudaGetLastError();
            return 1;
        }
        return sms;
    }();
    return count;
}

void synchronize() { check_cuda(cudaDeviceSynchronize(), "synchronize"); }

namespace {
DeviceArray<unsigned char>& cub_workspace_array() {
    static DeviceArray<unsigned char> workspace;
    return workspace;
}
}  // namespace

void* cub_workspace(std::size_t bytes) {
    DeviceArray<unsigned char>& workspace = cub_workspace_array();
    if (bytes > workspace.size()) workspace.resize(bytes + bytes / 2);
    return workspace.view().data();
}

std::size_t backend_scratch_bytes() { return cub_workspace_array().bytes(); }

// cudaFree waits for the device, so no kernel still uses the workspace when it goes.
void release_backend_scratch() { cub_workspace_array().release(); }

void* pinned_scratch(std::size_t bytes) {
    static void* buffer = nullptr;
    static std::size_t capacity = 0;
    if (bytes > capacity) {
        if (buffer) cudaFreeHost(buffer);
        buffer = nullptr;
        capacity = 0;  // until the new buffer exists: a failed allocation must not hand out the freed one
        const std::size_t wanted = bytes < 256 ? 256 : bytes;
        check_cuda(cudaMallocHost(&buffer, wanted), "pinned_scratch");
        capacity = wanted;
    }
    return buffer;
}

void sort_pairs(const char* name, View<const std::uint32_t> keys_in, View<std::uint32_t> keys_out,
                View<const std::uint32_t> values_in, View<std::uint32_t> values_out, int key_bits) {
    const std::int64_t n = static_cast<std::int64_t>(keys_in.size());
    if (n == 0) return;
    std::size_t temp_bytes = 0;
    check_cuda(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, keys_in.data(), keys_out.data(), values_in.data(),
                                               values_out.data(), n, 0, key_bits),
               name);
    void* temp = cub_workspace(temp_bytes);
    check_cuda(cub::DeviceRadixSort::SortPairs(temp, temp_bytes, keys_in.data(), keys_out.data(), values_in.data(),
                                               values_out.data(), n, 0, key_bits),
               name);
    check_launch(name);  // under MELTWATER_CUDA_SYNC a fault in the sort is reported as the sort's
}

StageTimers::StageTimers(int stage_count) : start_(stage_count), stop_(stage_count), used_(stage_count, 0) {
    for (int s = 0; s < stage_count; ++s) {
        check_cuda(cudaEventCreate(&start_[s]), "cudaEventCreate");
        check_cuda(cudaEventCreate(&stop_[s]), "cudaEventCreate");
    }
}
StageTimers::~StageTimers() {
    for (std::size_t s = 0; s < start_.size(); ++s) {
        cudaEventDestroy(start_[s]);
        cudaEventDestroy(stop_[s]);
    }
}
// One event pair per stage: a stage is timed once between two read()s (each runs once per step).
// The OpenMP timers add repeated intervals up; these would keep only the last one.
void StageTimers::start(int stage) { check_cuda(cudaEventRecord(start_[stage]), "StageTimers::start"); }
void StageTimers::stop(int stage) {
    check_cuda(cudaEventRecord(stop_[stage]), "StageTimers::stop");
    used_[stage] = 1;
}
void StageTimers::read(double* ms_out) {
    for (std::size_t s = 0; s < start_.size(); ++s) {
        ms_out[s] = 0.0;
        if (!used_[s]) continue;
        float ms = 0.f;
        check_cuda(cudaEventSynchronize(stop_[s]), "StageTimers::read");
        check_cuda(cudaEventElapsedTime(&ms, start_[s], stop_[s]), "StageTimers::read");
        ms_out[s] = ms;
        used_[s] = 0;
    }
}

MW_BACKEND_END
