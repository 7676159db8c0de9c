// A fluid emitter's parameters (emitter.hpp): a disc releasing layers of fluid, scene key
// `emitters[i]`. Host-only.
#pragma once
#include "simulation/parameters.hpp"

namespace mw {

struct EmitterParams {
    Vec3 center{0, 0, 0};     // of the disc, m
    Vec3 direction{0, -1, 0}; // the stream's direction and the disc's normal (unit once read)
    Real radius = 0.05;       // of the disc, m
    Real speed = 1;           // m/s along direction
    double start = 0;         // s: the first layer leaves at start
    double end = 1;           // s: the last before end
    Real temperature = 20;    // C, with heat conduction
};

inline const ParamTable<EmitterParams>& emitter_keys() {
    using T = EmitterParams;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(vector_key<T>("emitters[]", "center", member(&T::center), ParamRange::any(), "m",
                                  "the disc's centre: inside the domain, r0/2 from its faces")
                        .must_be_given());
        t.push_back(vector_key<T>("emitters[]", "direction", member(&T::direction), ParamRange::any(), "",
                                  "the stream's direction (normalised) and the disc's normal; not zero")
                        .must_be_given());
        t.push_back(number_key<T>("emitters[]", "radius", member(&T::radius), ParamRange::positive(), "m",
                                  "the disc's radius (narrower than r0: one particle a layer)")
                        .must_be_given());
        t.push_back(number_key<T>("emitters[]", "speed", member(&T::speed), ParamRange{0, 1000, true, false}, "m/s",
                                  "along direction")
                        .must_be_given());
        t.push_back(number_key<T>("emitters[]", "start", member(&T::start), ParamRange{0, 1e6, false, false}, "s",
                                  "the first layer leaves then"));
        t.push_back(number_key<T>("emitters[]", "end", member(&T::end), ParamRange{0, 1e6, true, false}, "s",
                                  "the last layer leaves before then (later than start)")
                        .derive_default([](const ResolvedKeys& r) { return *r.find("run.end_time"); }, "run.end_time"));
        t.push_back(number_key<T>("emitters[]", "temperature", member(&T::temperature), ParamRange::celsius(), "C",
                                  "the stream's temperature, with heat.enabled")
                        .derive_default([](const ResolvedKeys& r) { return *r.find("fluid.temperature"); },
                                        "fluid.temperature"));
        return t;
    }();
    return table;
}

}  // namespace mw
