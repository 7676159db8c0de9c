// A pressure sensor's parameters (pressure_sensors.hpp): a square patch of a domain wall, scene
// key `pressure_sensors[i]`. Host-only.
#pragma once
#include "simulation/parameters.hpp"

namespace mw {

struct PressureSensorParams {
    Vec3 center{0, 0, 0};  // on a face of the domain, m
    Real size = 0;         // the patch's side, m
};

inline const ParamTable<PressureSensorParams>& pressure_sensor_keys() {
    using T = PressureSensorParams;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(vector_key<T>("pressure_sensors[]", "center", member(&T::center), ParamRange::any(), "m",
                                  "the patch's centre, on a face of the domain (within r0/2 of it)")
                        .must_be_given());
        t.push_back(number_key<T>("pressure_sensors[]", "size", member(&T::size), ParamRange::positive(), "m",
                                  "the square patch's side (in 2D the segment's length): the load on it over its area is the reading")
                        .derive_default([](const ResolvedKeys& r) { return ParamValue::of(2 * r.number("fluid.spacing")); },
                                        "2 fluid.spacing"));
        return t;
    }();
    return table;
}

}  // namespace mw
