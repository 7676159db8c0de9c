// A non-owning, trivially copyable window onto an array in backend memory. Kernels capture views
// by value (never `this`), which is what makes the same lambda valid on a GPU and on CPU threads.
#pragma once
#include "backend/config.hpp"

namespace mw {
template <class T>
struct View {
    T* ptr = nullptr;
    std::size_t count = 0;

    MW_INLINE T& operator[](std::size_t i) const { return ptr[i]; }
    MW_INLINE std::size_t size() const { return count; }
    MW_INLINE T* data() const { return ptr; }
    MW_INLINE operator View<const T>() const { return View<const T>{ptr, count}; }
};
}  // namespace mw
