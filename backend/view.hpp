// A non-owning, trivially copyable window onto an array in backend memory. Kernels capture views
// by value (never `this`), which is what makes the same lambda valid on a GPU and on CPU threads.
#pragma once
#include <type_traits>

#include "backend/config.hpp"

namespace mw {
template <class T>
struct View {
    T* ptr = nullptr;
    std::size_t count = 0;

    MW_INLINE T& operator[](std::size_t i) const { return ptr[i]; }
    MW_INLINE std::size_t size() const { return count; }
    MW_INLINE T* data() const { return ptr; }
    // A mutable view converts to a read-only one (only defined for non-const T).
    template <class U = T, class = std::enable_if_t<!std::is_const_v<U>>>
    MW_INLINE operator View<const U>() const {
        return View<const U>{ptr, count};
    }
};
}  // namespace mw
