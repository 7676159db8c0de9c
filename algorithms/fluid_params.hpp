// The fluid module's parameters (fluid.hpp): the fluid (scene section `fluid`) and its solver
// (`solver`), with their scene keys. Host-only.
#pragma once
#include "algorithms/sph_kernels.hpp"
#include "simulation/parameters.hpp"

namespace mw {

enum class TimeStepMode { kFixed, kCfl };

struct FluidParams {
    Real rest_density = 1000;  // rho0, kg/m3
    Real spacing = 0.02;       // r0, m
    Real support_radius = 0.04;  // h, m
    KernelKind kernel = KernelKind::kCubicSpline;  // W for density and pressure (sph_kernels.hpp)
    Real viscosity = 0;       // mu, Pa s (Eq. 4)
    Real wall_viscosity = 0;  // mu of fluid-wall friction, Pa s (Eq. 8); 0: free-slip walls
};

struct SolverParams {
    Real dt = 0.001;  // s: the fixed step, or the largest step in CFL mode
    TimeStepMode dt_mode = TimeStepMode::kFixed;
    Real cfl_number = 0.4;  // CFL mode: a particle moves at most cfl r0 a step (step_size.hpp)
    Real dt_min = 1e-6;     // CFL mode never goes below min(this, dt)
    Real eta = 0.01;        // PCISPH stops when the average density error < eta
    // ... and, when positive, the largest one < eta_max. 0 here, so that tests and benchmarks that
    // build their parameters in code state the rule they run under; scenes default to 5 eta.
    Real eta_max = 0;
    int min_iterations = 3;
    int max_iterations = 100;
    // CFL mode: a step that held after more than this many PCISPH iterations lowers the largest
    // step to 3/4 of itself (step_size.hpp); 0: off. Twice min_iterations by default.
    int shorten_above_iterations = 6;
    // The longest step an elastic object's shape matching takes, s; 0: one per step (the paper's).
    // LSM's pull toward the goal is α (g - x)/Δt, so a body's sag under a load grows as Δt²: with
    // a positive value a longer step runs the solids in equal substeps no longer than it, and the
    // sag no longer depends on the step (solid_bodies.hpp, docs/lsm.md).
    Real solid_substep = 0;
    // Contact between moving solids (solid_collisions.hpp, docs/contact.md): on unless a scene
    // turns it off. Off, moving solids pass through one another; they still meet the domain's
    // faces, the static boxes and the static objects.
    bool solid_contact = true;
};

// The scenes' peak bound: 5 eta (5% at the default eta of 1%), off when that is 1 or more. On the
// default dam break it costs 1.6% more iterations and holds the largest per-step error at 4.9%
// (11.7% without); in CFL mode it keeps flat impacts from rebounding (docs/solver.md).
inline double default_eta_max(double eta) {
    const double peak = 5 * eta;
    return peak < 1 ? peak : 0.0;
}

inline const ParamTable<FluidParams>& fluid_keys() {
    using T = FluidParams;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(number_key<T>("fluid", "rest_density", member(&T::rest_density), ParamRange::positive(), "kg/m3",
                                  "rho0, the fluid's rest density"));
        t.push_back(number_key<T>("fluid", "spacing", member(&T::spacing), ParamRange::positive(), "m",
                                  "r0, the particle spacing")
                        .must_be_given());
        t.push_back(
            number_key<T>("fluid", "support_radius", member(&T::support_radius), ParamRange::positive(), "m",
                          "h, the kernel's support radius")
                .derive_default([](const ResolvedKeys& r) { return ParamValue::of(2 * r.number("fluid.spacing")); },
                                "2 x spacing")
                .derive_range(
                    [](const ResolvedKeys& r) {
                        const double r0 = r.number("fluid.spacing");
                        return ParamRange{r0, 4 * r0, true, false};
                    },
                    "(spacing, 4 x spacing]"));
        t.push_back(choice_key<T, KernelKind>(
            "fluid", "kernel", member(&T::kernel),
            {{kernel_name(KernelKind::kCubicSpline), KernelKind::kCubicSpline},
             {kernel_name(KernelKind::kWendlandC2), KernelKind::kWendlandC2}},
            "W for density and pressure; the cubic spline pairs up wider than 2.25 r0, Wendland C2 does not "
            "(docs/solver.md)"));
        t.push_back(number_key<T>("fluid", "viscosity", member(&T::viscosity), ParamRange::non_negative(), "Pa s",
                                  "mu of Eq. 4, mirrored across the domain walls"));
        t.push_back(number_key<T>("fluid", "wall_viscosity", member(&T::wall_viscosity), ParamRange::non_negative(),
                                  "Pa s", "mu of the friction with boundary particles (Eq. 8); 0: free-slip walls"));
        return t;
    }();
    return table;
}

inline const ParamTable<SolverParams>& solver_keys() {
    using T = SolverParams;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        // Below 1e-7 s a second of simulated time would take ten million steps: a typo, not a choice.
        t.push_back(number_key<T>("solver", "dt", member(&T::dt), ParamRange{1e-7, 1, false, false}, "s",
                                  "the step in fixed mode, the largest step in cfl mode"));
        t.push_back(choice_key<T, TimeStepMode>("solver", "dt_mode", member(&T::dt_mode),
                                                {{"fixed", TimeStepMode::kFixed}, {"cfl", TimeStepMode::kCfl}},
                                                "cfl: each step bounded by the CFL rule, halved when PCISPH fails "
                                                "(docs/solver.md)"));
        t.push_back(number_key<T>("solver", "cfl_number", member(&T::cfl_number), ParamRange{0, 1, true, false}, "",
                                  "cfl mode: a particle moves at most cfl_number r0 a step"));
        t.push_back(number_key<T>("solver", "eta", member(&T::eta), ParamRange{0, 1, true, true}, "",
                                  "PCISPH iterates until the average density error is below eta"));
        t.push_back(number_key<T>("solver", "eta_max", member(&T::eta_max), ParamRange{0, 1, false, true}, "",
                                  "... and the largest below eta_max; 0: no peak bound")
                        .derive_default(
                            [](const ResolvedKeys& r) { return ParamValue::of(default_eta_max(r.number("solver.eta"))); },
                            "5 x eta (0 when that is 1 or more)"));
        t.push_back(integer_key<T>("solver", "min_iterations", member(&T::min_iterations), 1, 1000,
                                   "PCISPH iterations at least"));
        t.push_back(integer_key<T>("solver", "max_iterations", member(&T::max_iterations), 1, 10000,
                                   "PCISPH iterations at most (and at least min_iterations)"));
        t.push_back(integer_key<T>("solver", "shorten_above_iterations", member(&T::shorten_above_iterations), 0, 10000,
                                   "cfl mode: a step that needed more PCISPH iterations than this lowers the largest "
                                   "step to 3/4 of itself (docs/solver.md); 0: off; else at least min_iterations")
                        .derive_default(
                            [](const ResolvedKeys& r) { return ParamValue::of(2 * r.number("solver.min_iterations")); },
                            "2 x min_iterations"));
        t.push_back(number_key<T>("solver", "solid_substep", member(&T::solid_substep), ParamRange{0, 1, false, false},
                                  "s", "elastic objects' shape matching runs in substeps no longer than this (a pinned body's sag "
                                  "then does not depend on the step); 0: one per step (docs/lsm.md)"));
        t.push_back(boolean_key<T>("solver", "solid_contact", member(&T::solid_contact),
                                   "contact between moving solids (docs/contact.md); false: they pass through one "
                                   "another, and still meet the domain's faces, static boxes and static objects"));
        return t;
    }();
    return table;
}

}  // namespace mw
