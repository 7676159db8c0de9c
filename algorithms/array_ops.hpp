// Small whole-array operations used between stages.
#pragma once
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

// v[i] = value for i < count (the rest untouched).
template <class T>
void fill_prefix(View<T> v, std::size_t count, T value) {
    parallel_for("fill_prefix", count, [=] MW_HD(std::size_t i) { v[i] = value; });
}

// v[i] *= factor for i < count.
template <class T>
void scale_prefix(View<T> v, std::size_t count, T factor) {
    parallel_for("scale_prefix", count, [=] MW_HD(std::size_t i) { v[i] = v[i] * factor; });
}

MW_BACKEND_END
