// Non-template parts of the CUDA backend.
#include <cstdlib>

#define MW_BACKEND_CUDA
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

void check_cuda(cudaError_t status, const char* what) {
    if (status != cudaSuccess) {
        (void)cudaGetLastError();
        throw DeviceError(std::string("CUDA error in ") + what + ": " + cudaGetErrorString(status));
    }
}

bool debug_sync_enabled() {
    const char* flag = std::getenv("MELTWATER_CUDA_SYNC");
    return flag && flag[0] == '1';
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

std::int64_t device_memory_free() {
    std::size_t free_bytes = 0, total_bytes = 0;
    if (cudaMemGetInfo(&free_bytes, &total_bytes) != cudaSuccess) {
        (void)cudaGetLastError();
        return 0;
    }
    return static_cast<std::int64_t>(free_bytes);
}

DeviceContext::DeviceContext(int device) : device_(device), debug_sync_(debug_sync_enabled()) {
    activate();
    int sms = 0;
    if (cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device_) != cudaSuccess) {
        (void)cudaGetLastError();
        sms = 1;
    }
    multiprocessors_ = sms > 0 ? sms : 1;
}

// cudaFree (the workspace and result slot, after this) waits for the device, so no kernel still
// uses them when they go.
DeviceContext::~DeviceContext() {
    if (pinned_) cudaFreeHost(pinned_);
}

void DeviceContext::activate() const { check_cuda(cudaSetDevice(device_), "selecting the CUDA device"); }

std::string DeviceContext::description() const {
    cudaDeviceProp prop{};
    if (cudaGetDeviceProperties(&prop, device_) != cudaSuccess) {
        (void)cudaGetLastError();
        return "no CUDA device";
    }
    char text[256];
    std::snprintf(text, sizeof text, "%s (sm_%d%d, %.1f GiB)", prop.name, prop.major, prop.minor,
                  static_cast<double>(prop.totalGlobalMem) / (1024.0 * 1024.0 * 1024.0));
    return text;
}

void DeviceContext::check_launch(const char* name) const {
    check_cuda(cudaGetLastError(), name);
    if (debug_sync_) check_cuda(cudaDeviceSynchronize(), name);
}

std::size_t DeviceContext::scratch_bytes() const { return workspace_.bytes() + result_.bytes() + pinned_bytes_; }

void* DeviceContext::workspace(std::size_t bytes) const {
    if (bytes > workspace_.size()) workspace_.resize(bytes + bytes / 2);
    return workspace_.view().data();
}

void* DeviceContext::result_slot(std::size_t bytes) const {
    if (bytes > result_.size()) {
        result_.resize(bytes < 256 ? 256 : bytes);
        check_cuda(cudaMemset(result_.view().data(), 0, result_.size()), "reduction result");
    }
    return result_.view().data();
}

void* DeviceContext::pinned(std::size_t bytes) const {
    if (bytes > pinned_bytes_) {
        if (pinned_) cudaFreeHost(pinned_);
        pinned_ = nullptr;
        pinned_bytes_ = 0;  // until the new buffer exists: a failed allocation must not hand out the freed one
        const std::size_t wanted = bytes < 256 ? 256 : bytes;
        check_cuda(cudaMallocHost(&pinned_, wanted), "pinned host buffer");
        pinned_bytes_ = wanted;
    }
    return pinned_;
}

int DeviceContext::block_size(const void* kernel, std::size_t n) const {
    auto found = largest_block_.find(kernel);
    if (found == largest_block_.end()) {
        int best = 256;
        int min_grid = 0;
        if (cudaOccupancyMaxPotentialBlockSize(&min_grid, &best, kernel, 0, 0) != cudaSuccess) {
            (void)cudaGetLastError();
            best = 256;
        }
        best = best < 256 ? best : 256;
        found = largest_block_.emplace(kernel, best < 64 ? best : best / 32 * 32).first;
    }
    const std::size_t enough_blocks = 2 * static_cast<std::size_t>(multiprocessors_);
    int block = found->second;
    while (block > 64 && (n + block - 1) / block < enough_blocks) {
        const int half = block / 2 / 32 * 32;
        block = half > 64 ? half : 64;
    }
    return block;
}

void sort_pairs(const DeviceContext& device, const char* name, View<const std::uint32_t> keys_in,
                View<std::uint32_t> keys_out, View<const std::uint32_t> values_in, View<std::uint32_t> values_out,
                int key_bits) {
    const std::int64_t n = static_cast<std::int64_t>(keys_in.size());
    if (n == 0) return;
    std::size_t temp_bytes = 0;
    check_cuda(cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, keys_in.data(), keys_out.data(), values_in.data(),
                                               values_out.data(), n, 0, key_bits, device.stream()),
               name);
    void* temp = device.workspace(temp_bytes);
    check_cuda(cub::DeviceRadixSort::SortPairs(temp, temp_bytes, keys_in.data(), keys_out.data(), values_in.data(),
                                               values_out.data(), n, 0, key_bits, device.stream()),
               name);
    device.check_launch(name);  // under MELTWATER_CUDA_SYNC a fault in the sort is reported as the sort's
}

StageTimers::StageTimers(const DeviceContext& device, int stage_count)
    : stream_(device.stream()), start_(stage_count), stop_(stage_count), used_(stage_count, 0) {
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
void StageTimers::start(int stage) { check_cuda(cudaEventRecord(start_[stage], stream_), "StageTimers::start"); }
void StageTimers::stop(int stage) {
    check_cuda(cudaEventRecord(stop_[stage], stream_), "StageTimers::stop");
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
