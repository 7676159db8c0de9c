// The single entry point algorithms include. The build defines exactly one of MW_BACKEND_CUDA or
// MW_BACKEND_OPENMP per translation unit; everything after this include is backend-agnostic.
// Each backend lives in its own inline namespace (mw::cuda_backend, mw::openmp_backend) so that the same
// algorithm headers compiled twice and linked into one program never share a symbol.
#pragma once
#if defined(MW_BACKEND_CUDA)
#include "backend/cuda/backend_cuda.cuh"
#elif defined(MW_BACKEND_OPENMP)
#include "backend/openmp/backend_openmp.hpp"
#else
#error "define MW_BACKEND_CUDA or MW_BACKEND_OPENMP before including backend/backend.hpp"
#endif
