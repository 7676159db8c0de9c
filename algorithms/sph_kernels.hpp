// SPH smoothing kernels. A kernel is a small struct with W(r), grad W(r_vec) and the viscosity
// Laplacian; the solver is written against that shape and instantiated once per kernel, so the
// scene chooses one (`fluid.kernel`, KernelKind below) and a new kernel is one more struct here.
#pragma once
#include <cmath>
#include <type_traits>

#include "algorithms/vec3.hpp"

namespace mw {

constexpr Real kPi = Real(3.14159265358979323846);

// The scene's choice of smoothing kernel for the fluid (`fluid.kernel`).
//  - cubic spline (Monaghan): docs/method.md's kernel (the paper says only "a Gaussian-like kernel
//    with finite support radius h"), the default.
//  - Wendland C2 (Wendland 1995): no pairing instability at any neighbour count (Dehnen & Aly
//    2012). The cubic spline has one at wide supports: at the paper's h = 2.5 r0 (about 65
//    neighbours) particles under a deep column's pressure close in pairs below h/3, where its
//    gradient stops growing, and are then thrown out (docs/solver.md, "Kernels").
enum class KernelKind { kCubicSpline, kWendlandC2 };

inline const char* kernel_name(KernelKind kind) {
    return kind == KernelKind::kWendlandC2 ? "wendland_c2" : "cubic_spline";
}

// What every radial kernel shares: the forms the neighbour sums use, written once over a profile
// W(q) = Profile::W_of_q and its slope dW/dr = Profile::dW_of_q (q = r/h), and the Müller et al.
// (2003) viscosity Laplacian, which is a kernel of its own and the same whatever W is.
template <class Profile>
struct RadialKernel {
    Real h = 1;
    Real inv_h = 1;
    Real visc_scale = 0;  // 45 / (π h⁶) in 3D, 40 / (π h⁵) in 2D

    MW_INLINE Real W(Real r) const { return profile().W_of_q(r * inv_h); }
    // ∇_i W(x_i - x_j) for r_vec = x_i - x_j, |r_vec| = r (passed in because callers have it).
    MW_INLINE Vec3 grad_W(Vec3 r_vec, Real r) const {
        if (r <= Real(1e-9) * h) return Vec3{0, 0, 0};
        return (profile().dW_of_q(r * inv_h) / r) * r_vec;
    }
    // The forms the neighbour sums use: from |r_vec|², with no branch at all, and 0 by themselves
    // out of range, so a sum needs no test per neighbour (whether a neighbour is in range is
    // unpredictable; the branch-free sums measured twice as fast, docs/solver.md).
    MW_INLINE Real W_r2(Real r2) const { return profile().W_of_q(std::sqrt(r2) * inv_h); }
    // 0 also for r = 0 (a particle and itself). The division is not conditional (a conditional
    // one could trap, which stops the compiler from turning it into a select): r = 0 divides by 1
    // and is masked after.
    MW_INLINE Vec3 grad_W_r2(Vec3 r_vec, Real r2) const {
        const bool apart = r2 > Real(1e-18) * h * h;
        const Real r = std::sqrt(r2);
        const Real inv_r = apart ? Real(1) / (apart ? r : Real(1)) : Real(0);
        return (profile().dW_of_q(r * inv_h) * inv_r) * r_vec;
    }
    // -(dW/dr) / r: the weight of Brookshaw's Laplacian, ∇²A_i ≈ 2 Σ_j V_j (A_j - A_i) (this),
    // never negative (heat.hpp). From r², branch-free; 0 for r = 0 and out of range.
    MW_INLINE Real laplacian_weight_r2(Real r2) const {
        const bool apart = r2 > Real(1e-18) * h * h;
        const Real r = std::sqrt(r2);
        const Real inv_r = apart ? Real(1) / (apart ? r : Real(1)) : Real(0);
        return -profile().dW_of_q(r * inv_h) * inv_r;
    }
    // Laplacian of the viscosity kernel; never negative, so viscosity never injects energy.
    MW_INLINE Real laplacian_visc(Real r) const { return r < h ? visc_scale * (h - r) : Real(0); }
    // The same from r², branch-free like W_r2 (0 out of range by itself).
    MW_INLINE Real laplacian_visc_r2(Real r2) const {
        const Real gap = h - std::sqrt(r2);
        return visc_scale * (gap > Real(0) ? gap : Real(0));
    }

   protected:
    // The viscosity Laplacian's constant is that of Müller et al.'s kernel normalised in the
    // profile's dimensions: 45/(π h⁶) in 3D, 40/(π h⁵) in 2D.
    void set_support(Real support) {
        h = support;
        inv_h = Real(1) / support;
        if constexpr (Profile::kDimensions == 3)
            visc_scale = Real(45) / (kPi * support * support * support * support * support * support);
        else
            visc_scale = Real(40) / (kPi * support * support * support * support * support);
    }

   private:
    MW_INLINE const Profile& profile() const { return static_cast<const Profile&>(*this); }
};

// Cubic spline (Monaghan) with compact support h: W > 0 for r < h, normalised in D dimensions
// (2 or 3): σ = 8/(π h³) in 3D, 40/(7π h²) in 2D. A 2D scene's particles lie in the plane z = 0
// and its sums run over a plane's neighbours; masses and volumes are then per unit depth.
template <int D>
struct CubicSpline : RadialKernel<CubicSpline<D>> {
    static_assert(D == 2 || D == 3);
    static constexpr int kDimensions = D;
    Real sigma = 0;
    Real grad_scale = 0;  // 6 σ / h: 48/(π h⁴) in 3D, 240/(7π h³) in 2D

    static CubicSpline with_support(Real support) {
        CubicSpline k;
        k.set_support(support);
        if constexpr (D == 3) {
            k.sigma = Real(8) / (kPi * support * support * support);
            k.grad_scale = Real(48) / (kPi * support * support * support * support);
        } else {
            k.sigma = Real(40) / (Real(7) * kPi * support * support);
            k.grad_scale = Real(240) / (Real(7) * kPi * support * support * support);
        }
        return k;
    }
    // The two pieces without branches (selects only): a = max(1-q, 0), b = max(1/2-q, 0);
    // for q ≤ 1/2, 2(1-q)³ - 8(1/2-q)³ = 6(q³-q²) + 1; both vanish for q ≥ 1.
    MW_INLINE Real W_of_q(Real q) const {
        const Real a = Real(1) - q > Real(0) ? Real(1) - q : Real(0);
        const Real b = Real(0.5) - q > Real(0) ? Real(0.5) - q : Real(0);
        return sigma * (Real(2) * a * a * a - Real(8) * b * b * b);
    }
    // dW/dr: grad_scale (4b² - a²), i.e. (dW/dq)/h with dW/dq / σ = -6(1-q)² + 24 max(1/2-q, 0)²,
    // equal to 6q(3q-2) for q ≤ 1/2. Its magnitude is largest at q = 1/3.
    MW_INLINE Real dW_of_q(Real q) const {
        const Real a = Real(1) - q > Real(0) ? Real(1) - q : Real(0);
        const Real b = Real(0.5) - q > Real(0) ? Real(0.5) - q : Real(0);
        return grad_scale * (Real(4) * b * b - a * a);
    }
};

// Wendland C2 with compact support h, normalised in D dimensions: W = σ (1-q)⁴ (1+4q) with
// σ = 21/(2π h³) in 3D, 7/(π h²) in 2D.
template <int D>
struct WendlandC2 : RadialKernel<WendlandC2<D>> {
    static_assert(D == 2 || D == 3);
    static constexpr int kDimensions = D;
    Real sigma = 0;
    Real grad_scale = 0;  // 20 σ / h

    static WendlandC2 with_support(Real support) {
        WendlandC2 k;
        k.set_support(support);
        if constexpr (D == 3)
            k.sigma = Real(21) / (Real(2) * kPi * support * support * support);
        else
            k.sigma = Real(7) / (kPi * support * support);
        k.grad_scale = Real(20) * k.sigma / support;
        return k;
    }
    MW_INLINE Real W_of_q(Real q) const {
        const Real a = Real(1) - q > Real(0) ? Real(1) - q : Real(0);
        const Real a2 = a * a;
        return sigma * a2 * a2 * (Real(1) + Real(4) * q);
    }
    // dW/dr = -20 σ q (1-q)³ / h: d/dq [(1-q)⁴ (1+4q)] = -20 q (1-q)³. Largest in magnitude at q = 1/4.
    MW_INLINE Real dW_of_q(Real q) const {
        const Real a = Real(1) - q > Real(0) ? Real(1) - q : Real(0);
        return -grad_scale * q * a * a * a;
    }
};

using CubicSpline3D = CubicSpline<3>;
using CubicSpline2D = CubicSpline<2>;
using WendlandC2_3D = WendlandC2<3>;
using WendlandC2_2D = WendlandC2<2>;

// Kernels are captured by value in device lambdas.
static_assert(std::is_trivially_copyable_v<CubicSpline3D> && std::is_trivially_copyable_v<WendlandC2_3D> &&
              std::is_trivially_copyable_v<CubicSpline2D> && std::is_trivially_copyable_v<WendlandC2_2D>);

// Calls f(kernel) with the 3D kernel of `kind` and support h: where host code (the wall gap, a
// factory) turns the scene's choice into the type the solver is written against.
template <class F>
decltype(auto) with_kernel(KernelKind kind, Real support, F&& f) {
    if (kind == KernelKind::kWendlandC2) return f(WendlandC2_3D::with_support(support));
    return f(CubicSpline3D::with_support(support));
}

// The same with the scene's dimensions (2 or 3).
template <class F>
decltype(auto) with_kernel(KernelKind kind, int dimensions, Real support, F&& f) {
    if (dimensions == 2) {
        if (kind == KernelKind::kWendlandC2) return f(WendlandC2_2D::with_support(support));
        return f(CubicSpline2D::with_support(support));
    }
    return with_kernel(kind, support, f);
}

}  // namespace mw
