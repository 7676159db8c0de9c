// CUDA backend: cudaMalloc'd arrays, one templated kernel for parallel_for with a block size chosen
// once per kernel and device, CUB reductions/scans/sorts on the context's persistent workspace (no
// per-call device allocation), CUDA-event stage timers. Same API, name for name, as backend/openmp/backend_openmp.hpp.
#pragma once
#include <cuda_runtime.h>

#include <cub/device/device_radix_sort.cuh>
#include <cub/device/device_reduce.cuh>
#include <cub/device/device_scan.cuh>
#include <thrust/iterator/counting_iterator.h>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

#include "backend/config.hpp"
#include "backend/device_array.hpp"
#include "common/errors.hpp"
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

// Default for neighbors.lists "auto" (NeighborParams::Lists::kAuto): gathering from the sorted grid keeps memory per particle low; lists are to be measured on a GPU.
constexpr bool kPrefersNeighborLists = false;

constexpr const char* kBackendName = "cuda";

bool backend_available();          // a CUDA device is present and usable
std::string unavailable_reason();  // why not, in the driver's words ("" when available)
std::int64_t device_memory_free(); // of the current device, bytes
// Set MELTWATER_CUDA_SYNC=1 to synchronise and check after every launch (debug mode, as PBRT).
bool debug_sync_enabled();
void check_cuda(cudaError_t status, const char* what);

// GPU global memory, on the device current on the calling thread (DeviceContext::activate).
struct CudaSpace {
    static void* allocate(std::size_t bytes) {
        void* p = nullptr;
        const cudaError_t status = cudaMalloc(&p, bytes);
        if (status == cudaErrorMemoryAllocation) {
            (void)cudaGetLastError();
            throw DeviceError("out of GPU memory allocating " + std::to_string(bytes) + " bytes (" +
                              std::to_string(device_memory_free()) + " bytes free on the device)");
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
    static void fill(T* p, std::size_t n, T value);  // after the kernels, below
};

template <class T>
using DeviceArray = BasicDeviceArray<T, CudaSpace>;

// Everything one simulation's launches share on a GPU: the device and the stream they run on,
// CUB's workspace, a pinned host buffer and a device slot for reduction results, and each kernel's
// block size. A simulation owns one and passes it to every launch; two simulations in one process
// share nothing, so each may live on a device of its own. The stream is the device's legacy
// default stream, so that the arrays' plain copies stay ordered with the launches.
class DeviceContext {
   public:
    explicit DeviceContext(int device = 0);
    ~DeviceContext();
    DeviceContext(const DeviceContext&) = delete;
    DeviceContext& operator=(const DeviceContext&) = delete;

    int device() const { return device_; }
    cudaStream_t stream() const { return stream_; }
    int multiprocessors() const { return multiprocessors_; }
    std::string description() const;  // e.g. "NVIDIA H100 80GB HBM3 (sm_90, 79.1 GiB)"
    // Makes this context's device current on the calling thread: a simulation calls it on entry.
    void activate() const;
    void synchronize() const { check_cuda(cudaStreamSynchronize(stream_), "synchronize"); }
    void check_launch(const char* name) const;
    // Bytes held between calls: CUB's workspace (the radix sort's is the large one, about 8 bytes
    // per sorted item, kept with half again as headroom), the pinned buffer and the result slot.
    std::size_t scratch_bytes() const;

    void* workspace(std::size_t bytes) const;   // CUB's temporary storage; grows, never shrinks
    void* pinned(std::size_t bytes) const;      // small pinned host memory for reduction results
    void* result_slot(std::size_t bytes) const; // device memory for one reduction result, zeroed once
    // The block size for `kernel` launched over n items (parallel_for): the occupancy
    // calculator's choice, computed once per kernel on this device, capped at 256 (it returns the
    // largest block that reaches full occupancy, up to 1024, which leaves most multiprocessors idle
    // on small scenes) and kept a whole number of warps; then halved, down to 64 and in whole
    // warps, until the launch has at least two blocks per multiprocessor.
    int block_size(const void* kernel, std::size_t n) const;

   private:
    int device_ = 0;
    cudaStream_t stream_ = 0;
    int multiprocessors_ = 1;
    bool debug_sync_ = false;  // MELTWATER_CUDA_SYNC, read once
    mutable DeviceArray<unsigned char> workspace_, result_;
    mutable void* pinned_ = nullptr;
    mutable std::size_t pinned_bytes_ = 0;
    mutable std::unordered_map<const void*, int> largest_block_;
};

template <class F>
__global__ void parallel_for_kernel(std::size_t n, F f) {
    const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < n) f(i);
}

template <class F>
void parallel_for(const DeviceContext& device, const char* name, std::size_t n, F f) {
    if (n == 0) return;
    const int block = device.block_size(reinterpret_cast<const void*>(parallel_for_kernel<F>), n);
    const std::size_t grid = (n + block - 1) / block;
    parallel_for_kernel<F><<<static_cast<unsigned>(grid), block, 0, device.stream()>>>(n, f);
    device.check_launch(name);
}

template <class T>
__global__ void fill_kernel(T* p, std::size_t n, T value) {
    const std::size_t i = static_cast<std::size_t>(blockIdx.x) * blockDim.x + threadIdx.x;
    if (i < n) p[i] = value;
}

// On the legacy default stream, which every context's launches share (DeviceContext).
template <class T>
void CudaSpace::fill(T* p, std::size_t n, T value) {
    if (n == 0) return;
    fill_kernel<T><<<static_cast<unsigned>((n + 255) / 256), 256>>>(p, n, value);
    check_cuda(cudaGetLastError(), "DeviceArray::fill");
    if (debug_sync_enabled()) check_cuda(cudaDeviceSynchronize(), "DeviceArray::fill");
}

// Applies f to an index; lets CUB read f(i) through a counting iterator.
template <class T, class F>
struct IndexTransform {
    F f;
    __device__ T operator()(std::size_t i) const { return f(i); }
};

// CUB's reduction has a fixed order for a given size and device, so results are reproducible.
template <class T, class Op, class F>
T transform_reduce(const DeviceContext& device, const char* name, std::size_t n, T identity, Op op, F f) {
    if (n == 0) return identity;
    // Zeroed once (result_slot): CUB writes only T's members, and copying back padding it never
    // wrote (a float build's DensityError) would be an uninitialised read to compute-sanitizer's
    // initcheck.
    T* result = static_cast<T*>(device.result_slot(sizeof(T)));
    thrust::counting_iterator<std::size_t> first(0);
    IndexTransform<T, F> transform{f};
    std::size_t temp_bytes = 0;
    check_cuda(cub::DeviceReduce::TransformReduce(nullptr, temp_bytes, first, result, static_cast<std::int64_t>(n),
                                                  op, transform, identity, device.stream()),
               name);
    void* temp = device.workspace(temp_bytes);
    check_cuda(cub::DeviceReduce::TransformReduce(temp, temp_bytes, first, result, static_cast<std::int64_t>(n), op,
                                                  transform, identity, device.stream()),
               name);
    T* host = static_cast<T*>(device.pinned(sizeof(T)));
    check_cuda(cudaMemcpyAsync(host, result, sizeof(T), cudaMemcpyDeviceToHost, device.stream()), name);
    check_cuda(cudaStreamSynchronize(device.stream()), name);
    return *host;
}

// Returns the total. The last input (read before the scan, which may work in place) and the last
// output are copied into pinned memory on the stream, so the call costs one synchronisation.
template <class T>
T exclusive_scan(const DeviceContext& device, const char* name, View<const T> in, View<T> out) {
    const std::size_t n = in.size();
    if (n == 0) return T(0);
    T* ends = static_cast<T*>(device.pinned(2 * sizeof(T)));
    check_cuda(cudaMemcpyAsync(&ends[0], in.data() + n - 1, sizeof(T), cudaMemcpyDeviceToHost, device.stream()), name);
    std::size_t temp_bytes = 0;
    check_cuda(cub::DeviceScan::ExclusiveSum(nullptr, temp_bytes, in.data(), out.data(), static_cast<std::int64_t>(n),
                                             device.stream()),
               name);
    void* temp = device.workspace(temp_bytes);
    check_cuda(cub::DeviceScan::ExclusiveSum(temp, temp_bytes, in.data(), out.data(), static_cast<std::int64_t>(n),
                                             device.stream()),
               name);
    check_cuda(cudaMemcpyAsync(&ends[1], out.data() + n - 1, sizeof(T), cudaMemcpyDeviceToHost, device.stream()), name);
    check_cuda(cudaStreamSynchronize(device.stream()), name);
    return ends[0] + ends[1];
}

void sort_pairs(const DeviceContext& device, const char* name, View<const std::uint32_t> keys_in,
                View<std::uint32_t> keys_out, View<const std::uint32_t> values_in, View<std::uint32_t> values_out,
                int key_bits);

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
    StageTimers(const DeviceContext& device, int stage_count);
    ~StageTimers();
    StageTimers(const StageTimers&) = delete;
    StageTimers& operator=(const StageTimers&) = delete;
    void start(int stage);
    void stop(int stage);
    void read(double* ms_out);

   private:
    cudaStream_t stream_ = 0;
    std::vector<cudaEvent_t> start_, stop_;
    std::vector<char> used_;
};

MW_BACKEND_END
