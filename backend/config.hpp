// Compile-time configuration shared by every backend: the host/device annotation and the scalar
// type. Nothing here knows which backend is being compiled.
#pragma once
#include <cstddef>
#include <cstdint>

// MW_INLINE is a hint to the host compiler; MW_ALWAYS_INLINE insists, for the few small functions
// on a per-particle path that g++ otherwise calls out of line (wall_contact.hpp says what it cost).
#if defined(__CUDACC__)
#define MW_HD __host__ __device__
#define MW_INLINE __host__ __device__ __forceinline__
#define MW_ALWAYS_INLINE __host__ __device__ __forceinline__
#else
#define MW_HD
#define MW_INLINE inline
#define MW_ALWAYS_INLINE inline __attribute__((always_inline))
#endif

namespace mw {
// One alias for the simulation scalar so that a double-precision build is one configure switch
// (-DMELTWATER_DOUBLE=ON): precision is one of the speed/accuracy trades users measure.
#if defined(MW_DOUBLE)
using Real = double;
#else
using Real = float;
#endif
}  // namespace mw
