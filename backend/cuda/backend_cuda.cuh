// CUDA backend: cudaMalloc'd arrays, one templated kernel for parallel_for with a block size chosen
// once per lambda type, CUB reductions/scans/sorts on a persistent workspace (no per-call device
// allocation), CUDA-event stage timers. Same API, name for name, as backend/openmp/backend_openmp.hpp.
#pragma once
#include <cuda_runtime.h>

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>
#include <thrust/iterator/counting_iterator.h>
#include <string>
#include <utility>
#include <vector>

#include "backend/config.hpp"
#include "backend/device_array.hpp"
#include "backend/errors.hpp"
#include "backend/memory_ledger.hpp"
#include "backend/reduce_ops.hpp"
#include "backend/view.hpp"

// The inline namespace is mw::cuda_backend, not mw::cuda: with `using namespace mw;` at global
// scope in a .cu file, a namespace named cuda would make nvcc's references to libcu++'s ::cuda
// ambiguous.
#define MW_BACKEND_BEGIN \
    namespace mw {       \
    inline namespace cuda_backend {
#define MW_BACKEND_END \
    }                  \
    }

MW_BACKEND_BEGIN

// Default for SimulationParams::neighbor_lists = kAuto: gathering from the sorted grid keeps memory per particle low; lists are to be measured on a GPU.
constexpr bool kPrefersNeighborLists = false;

constexpr const char* kBackendName = "cuda";

inline MemoryLedger& memory_ledger() {
    static MemoryLedger ledger;
    return ledger;
}

void set_threads(int threads);  // no effect on the GPU; kept for a uniform command line
int thread_count();
bool backend_available();          // a CUDA device is present and usable
std::string unavailable_reason();  // why not, in the driver's words ("" when available)
std::string device_description();  // e.g. "NVIDIA H100 80GB HBM3 (sm_90, 79.1 GiB)"
std::int64_t device_memory_free();
int multiprocessor_count();  // of the current device, read once
void synchronize();
// Set MELTWATER_CUDA_SYNC=1 to synchronise and check after every launch (debug mode, as PBRT).
bool debug_sync_enabled();
void check_cuda(cudaError_t status, const char* what);
void check_launch(const char* name);

// Scratch memory shared by every CUB call of this backend; grows, never shrinks.
void* cub_workspace(std::size_t bytes);
// A small pinned host buffer for reduction results, so a reduction costs one small copy.
void* pinned_scratch(std::size_t bytes);

// GPU global memory.
struct CudaSpace {
    static void* allocate(std::size_t bytes) {
        void* p = nullptr;
        const cudaError_t status = cudaMalloc(&p, bytes);
        if (status == cudaErrorMemoryAllocation) {
            (void)cudaGetLastError();
            throw DeviceError("out of GPU memory allocating " + std::to_string(bytes) + " bytes (" +
                              std::to_string(memory_ledger().current.load()) + " bytes already held, " +
                              std::to_string(device_memory_free()) + " free)");
        }
        // Anything else (often an error left by an earlier kernel) is not a memory shortage.
        check_cuda(status, "allocating GPU memory");
        return p;
    }
    static void release(void* p) { cudaFree(p); }
    static void to_device(void* dst, const void* src, std::size_t bytes) {
        check_cuda(cudaMemcpy(dst, src, bytes, cudaMemcpyHostToDevice), "copy to the GPU");
    }
    static void to_host(void* dst, const void* src, std::size_t bytes) {
        check_cuda(cudaMemcpy(dst, src, bytes, cudaMemcpyDeviceToHost), "copy from the GPU");
    }
    static void within(void* dst, const void* src, std::size_t bytes) {
        check_cuda(cudaMemcpy(dst, src, bytes, cudaMemcpyDeviceToDevice), "copy on the GPU");
    }
    template <class T>
    static void fill(T* p, std::size_t n, T value);  // after parallel_for, below
    static MemoryLedger& ledger() { return memory_ledger(); }
};

template <class T>
using DeviceArray = BasicDeviceArray<T, CudaSpace>;

template <class F>
__global__ void parallel_for_kernel(std::size_t n, F f) {
    const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < n) f(i);
}

// Block size: the occupancy calculator's choice for the kernel, computed once per lambda type,
// capped at 256 (it returns the largest block that reaches full occupancy, up to 1024, which
// leaves most multiprocessors idle on small scenes) and kept a whole number of warps; then halved,
// down to 64 and in whole warps, until the launch has at least two blocks per multiprocessor.
template <class F>
int block_size_for(std::size_t n) {
    static const int largest = [] {
        int min_grid = 0, best = 256;
        if (cudaOccupancyMaxPotentialBlockSize(&min_grid, &best, parallel_for_kernel<F>, 0, 0) != cudaSuccess) {
            (void)cudaGetLastError();
            best = 256;
        }
        best = best < 256 ? best : 256;
        return best < 64 ? best : best / 32 * 32;
    }();
    const std::size_t enough_blocks = 2 * static_cast<std::size_t>(multiprocessor_count());
    int block = largest;
    while (block > 64 && (n + block - 1) / block < enough_blocks) {
        const int half = block / 2 / 32 * 32;
        block = half > 64 ? half : 64;
    }
    return block;
}

template <class F>
void parallel_for(const char* name, std::size_t n, F f) {
    if (n == 0) return;
    const int block = block_size_for<F>(n);
    const std::size_t grid = (n + block - 1) / block;
    parallel_for_kernel<F><<<static_cast<unsigned>(grid), block>>>(n, f);
    check_launch(name);
}

template <class T>
void CudaSpace::fill(T* p, std::size_t n, T value) {
    parallel_for("DeviceArray::fill", n, [=] __device__(std::size_t i) { p[i] = value; });
}

// Applies f to an index; lets CUB read f(i) through a counting iterator.
template <class T, class F>
struct IndexTransform {
    F f;
    __device__ T operator()(std::size_t i) const { return f(i); }
};

// CUB's reduction has a fixed order for a given size and device, so results are reproducible.
template <class T, class Op, class F>
T transform_reduce(const char* name, std::size_t n, T identity, Op op, F f) {
    if (n == 0) return identity;
    // Zeroed once: CUB writes only T's members, and copying back padding it never wrote (a float
    // build's DensityError) would be an uninitialised read to compute-sanitizer's initcheck.
    static DeviceArray<T> device_result = [] {
        DeviceArray<T> result(1);
        check_cuda(cudaMemset(result.view().data(), 0, sizeof(T)), "reduction result");
        return result;
    }();
    thrust::counting_iterator<std::size_t> first(0);
    IndexTransform<T, F> transform{f};
    std::size_t temp_bytes = 0;
    check_cuda(cub::DeviceReduce::TransformReduce(nullptr, temp_bytes, first, device_result.view().data(),
                                                  static_cast<std::int64_t>(n), op, transform, identity),
               name);
    void* temp = cub_workspace(temp_bytes);
    check_cuda(cub::DeviceReduce::TransformReduce(temp, temp_bytes, first, device_result.view().data(),
                                                  static_cast<std::int64_t>(n), op, transform, identity),
               name);
    T* host = static_cast<T*>(pinned_scratch(sizeof(T)));
    check_cuda(cudaMemcpy(host, device_result.view().data(), sizeof(T), cudaMemcpyDeviceToHost), name);
    return *host;
}

// Returns the total. The last input (read before the scan, which may work in place) and the last
// output are copied into pinned memory on the stream, so the call costs one synchronisation.
template <class T>
T exclusive_scan(const char* name, View<const T> in, View<T> out) {
    const std::size_t n = in.size();
    if (n == 0) return T(0);
    T* ends = static_cast<T*>(pinned_scratch(2 * sizeof(T)));
    check_cuda(cudaMemcpyAsync(&ends[0], in.data() + n - 1, sizeof(T), cudaMemcpyDeviceToHost), name);
    std::size_t temp_bytes = 0;
    check_cuda(cub::DeviceScan::ExclusiveSum(nullptr, temp_bytes, in.data(), out.data(), static_cast<std::int64_t>(n)),
               name);
    void* temp = cub_workspace(temp_bytes);
    check_cuda(cub::DeviceScan::ExclusiveSum(temp, temp_bytes, in.data(), out.data(), static_cast<std::int64_t>(n)),
               name);
    check_cuda(cudaMemcpyAsync(&ends[1], out.data() + n - 1, sizeof(T), cudaMemcpyDeviceToHost), name);
    check_cuda(cudaStreamSynchronize(0), name);
    return ends[0] + ends[1];
}

void sort_pairs(const char* name, View<const std::uint32_t> keys_in, View<std::uint32_t> keys_out,
                View<const std::uint32_t> values_in, View<std::uint32_t> values_out, int key_bits);

// Scratch the backend keeps between calls and that no DeviceArray owner counts: CUB's workspace,
// shared by every sort, scan and reduction of the process (the radix sort's is the large one,
// about 8 bytes per sorted item, held with half again as headroom). Grows while a simulation
// lives; release_backend_scratch (called when the last one goes, backend/scratch_user.hpp) frees
// it.
std::size_t backend_scratch_bytes();
void release_backend_scratch();

// Atomics are called from host/device lambdas; only the device path runs on this backend.
#if defined(__CUDA_ARCH__)
#define MW_DEVICE_OR_HOST(device_expr, host_expr) device_expr
#else
#define MW_DEVICE_OR_HOST(device_expr, host_expr) host_expr
#endif
MW_INLINE void atomic_add(int* address, int value) {
    MW_DEVICE_OR_HOST(atomicAdd(address, value), __atomic_fetch_add(address, value, __ATOMIC_RELAXED));
}
MW_INLINE void atomic_add(unsigned* address, unsigned value) {
    MW_DEVICE_OR_HOST(atomicAdd(address, value), __atomic_fetch_add(address, value, __ATOMIC_RELAXED));
}
MW_INLINE void atomic_add(float* address, float value) {
    MW_DEVICE_OR_HOST(atomicAdd(address, value), (void)(*address += value));
}
MW_INLINE void atomic_add(double* address, double value) {
    MW_DEVICE_OR_HOST(atomicAdd(address, value), (void)(*address += value));
}

// Stage timers on CUDA events: no synchronisation until read(), once per step.
class StageTimers {
   public:
    explicit StageTimers(int stage_count);
    ~StageTimers();
    StageTimers(const StageTimers&) = delete;
    StageTimers& operator=(const StageTimers&) = delete;
    void start(int stage);
    void stop(int stage);
    void read(double* ms_out);

   private:
    std::vector<cudaEvent_t> start_, stop_;
    std::vector<char> used_;
};

MW_BACKEND_END
