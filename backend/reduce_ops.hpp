// Reduction operators usable on host and device. A reduction takes one of these plus its identity.
#pragma once
#include "backend/config.hpp"

namespace mw {
struct SumOp {
    template <class T>
    MW_INLINE T operator()(const T& a, const T& b) const { return a + b; }
};
struct MinOp {
    template <class T>
    MW_INLINE T operator()(const T& a, const T& b) const { return b < a ? b : a; }
};
struct MaxOp {
    template <class T>
    MW_INLINE T operator()(const T& a, const T& b) const { return a < b ? b : a; }
};
}  // namespace mw
