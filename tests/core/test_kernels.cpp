// Kernel normalisation, gradient antisymmetry, and PCISPH's δ against METHOD.md's check values.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "algorithms/pcisph_delta.hpp"
#include "algorithms/sph_kernels.hpp"

using namespace mw;

TEST_CASE("cubic spline 3D integrates to one") {
    const double h = 0.1, step = h / 40;
    const CubicSpline3D kernel = CubicSpline3D::with_support(Real(h));
    double integral = 0;
    for (double x = -h; x <= h; x += step)
        for (double y = -h; y <= h; y += step)
            for (double z = -h; z <= h; z += step)
                integral += kernel.W(Real(std::sqrt(x * x + y * y + z * z))) * step * step * step;
    CHECK(integral == doctest::Approx(1.0).epsilon(2e-3));
}

TEST_CASE("cubic spline 2D integrates to one") {
    const double h = 0.1, step = h / 200;
    const CubicSpline2D kernel = CubicSpline2D::with_support(Real(h));
    double integral = 0;
    for (double x = -h; x <= h; x += step)
        for (double y = -h; y <= h; y += step) integral += kernel.W(Real(std::sqrt(x * x + y * y))) * step * step;
    CHECK(integral == doctest::Approx(1.0).epsilon(2e-3));
}

TEST_CASE("kernel gradient is antisymmetric, points inward and matches finite differences") {
    const CubicSpline3D kernel = CubicSpline3D::with_support(Real(0.1));
    const Vec3 samples[] = {{0.01f, 0.02f, -0.03f}, {0.04f, 0.0f, 0.01f}, {-0.06f, 0.05f, 0.02f}, {0.0f, 0.0f, 0.09f}};
    for (Vec3 r : samples) {
        const Real d = norm(r);
        const Vec3 g = kernel.grad_W(r, d), g_minus = kernel.grad_W(-r, d);
        CHECK(g.x == doctest::Approx(-g_minus.x));
        CHECK(g.y == doctest::Approx(-g_minus.y));
        CHECK(g.z == doctest::Approx(-g_minus.z));
        CHECK(dot(g, r) < 0);  // W decreases outward
        const Real eps = 1e-4f;
        const Real fd = (kernel.W(d + eps) - kernel.W(d - eps)) / (2 * eps);
        CHECK(norm(g) == doctest::Approx(std::fabs(fd)).epsilon(1e-2));
    }
    CHECK(norm(kernel.grad_W(Vec3{0, 0, 0}, 0)) == 0);
    CHECK(kernel.W(Real(0.1)) == 0);
}

TEST_CASE("the branch-free forms the neighbour sums use equal W and grad W, and vanish out of range") {
    const Real h = Real(0.1);
    const CubicSpline3D kernel = CubicSpline3D::with_support(h);
    double worst_w = 0, worst_grad = 0;
    for (int k = 1; k <= 400; ++k) {
        // Directions vary with k; distances run from near 0 to 1.2 h, across q = 1/2 and q = 1.
        const Real d = h * Real(k) / Real(333);
        const Vec3 raw{std::cos(Real(k)), std::sin(Real(0.7) * Real(k)), Real(0.3)};
        const Vec3 dir = raw / norm(raw);
        const Vec3 r = d * dir;
        const Real r2 = norm2(r);
        worst_w = std::max(worst_w, double(std::fabs(kernel.W_r2(r2) - kernel.W(d))) / double(kernel.W(0)));
        worst_grad = std::max(worst_grad, double(norm(kernel.grad_W_r2(r, r2) - kernel.grad_W(r, d))) /
                                              double(kernel.grad_scale));
        if (d >= h) {
            CHECK(kernel.W_r2(r2) == 0);
            CHECK(norm(kernel.grad_W_r2(r, r2)) == 0);
        }
    }
    CHECK(worst_w < 1e-5);
    CHECK(worst_grad < 1e-5);
    CHECK(kernel.W_r2(0) == doctest::Approx(double(kernel.W(0))));
    CHECK(norm(kernel.grad_W_r2(Vec3{0, 0, 0}, 0)) == 0);  // a particle and itself: no force
}

TEST_CASE("PCISPH delta matches the check values of METHOD.md") {
    const double r0 = 0.02, dt = 0.003, rho0 = 1000;
    {
        const CubicSpline3D kernel = CubicSpline3D::with_support(Real(2 * r0));
        const PrototypeSums sums = prototype_sums(kernel, r0, 3);
        const double delta = pcisph_delta(sums, rho0, rho0 * r0 * r0 * r0, dt);
        CHECK(delta == doctest::Approx(r0 * r0 / (0.849680 * dt * dt)).epsilon(1e-4));
        CHECK(sums.grad_sum_sq < 1e-6 * sums.sum_grad_sq);  // full neighbourhood: Σ∇W = 0
    }
    {
        const CubicSpline2D kernel = CubicSpline2D::with_support(Real(2 * r0));
        const PrototypeSums sums = prototype_sums(kernel, r0, 2);
        const double delta = pcisph_delta(sums, rho0, rho0 * r0 * r0, dt);
        CHECK(delta == doctest::Approx(r0 * r0 / (1.040066 * dt * dt)).epsilon(1e-4));
    }
}
