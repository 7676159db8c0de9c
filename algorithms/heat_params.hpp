// Heat conduction's parameters (heat.hpp): scene section `heat`, and the fluid's material in
// `fluid`. Host-only.
#pragma once
#include "simulation/parameters.hpp"

namespace mw {

struct HeatParams {
    // Heat conduction among the fluid and the moving solids; without it no temperature is stored.
    bool enabled = false;
    Real fluid_diffusivity = Real(1.43e-7);  // alpha of the fluid, m2/s (water at 20 C)
    Real fluid_capacity = Real(4.18e6);      // rho c of the fluid, J/(m3 K) (water)
    // Explicit sub-steps per step: as many as keep every particle's update a mean of its
    // neighbours' temperatures as the scene starts, at most this.
    int max_substeps = 32;
};

inline const ParamTable<HeatParams>& heat_keys() {
    using T = HeatParams;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(number_key<T>("fluid", "thermal_diffusivity", member(&T::fluid_diffusivity),
                                  ParamRange::non_negative(), "m2/s",
                                  "alpha of the fluid (water's at 20 C), with heat.enabled; the objects' default"));
        t.push_back(number_key<T>("fluid", "heat_capacity", member(&T::fluid_capacity), ParamRange::positive(),
                                  "J/(m3 K)", "rho c of the fluid (water's), with heat.enabled; the objects' default"));
        t.push_back(boolean_key<T>("heat", "enabled", member(&T::enabled),
                                   "heat conduction among the fluid and the elastic and rigid objects (docs/heat.md)"));
        t.push_back(integer_key<T>("heat", "max_substeps", member(&T::max_substeps), 1, 1000,
                                   "explicit sub-steps a step may take at most"));
        return t;
    }();
    return table;
}

}  // namespace mw
