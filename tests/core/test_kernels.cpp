// Kernel normalisation, gradient antisymmetry, and PCISPH's δ against METHOD.md's check values.
#include <doctest/doctest.h>

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
