// How fluid and moving solids act on each other (two_way_coupling.hpp, solid_correction.hpp,
// solid_bodies.hpp), scene section `coupling`. Host-only.
#pragma once
#include "simulation/parameters.hpp"

namespace mw {

// The paper's method by default: each switch turns a part of it off.
struct CouplingParams {
    // The forces the fluid feels from a moving solid's boundary particles act back on the solid.
    bool two_way = true;
    // The velocity-position correction against elastic and rigid objects' surface particles.
    bool correction = true;
    Real slip = 1;  // the correction's tangential rule: 1 free slip, 0 no slip
    // PCISPH meets the moving solids' boundary particles where they will be at the end of the step.
    bool predict_solids = true;
    // Rigid and solid elastic objects answer the fluid's pressure inside the PCISPH iterations,
    // each as one body (with predict_solids): each iteration meets them where gravity and the last
    // iterations' pressure take them.
    bool strong = true;
    // Rigid and elastic objects' surface particles sit inside their mesh's face by the walls' gap
    // (sampling/surface_inset.hpp), so that the fluid rests at the face as it does at a wall; a
    // thin elastic object's stay on its faces (apps/scene_builder.cpp).
    bool surface_inset = true;
    // In a scene with fluid, moving objects that start clear of them stop a fluid layer (1.5 r0)
    // short of the domain walls and the static boxes instead of touching them (docs/contact.md,
    // "The film"; algorithms/lsm_regions.hpp, object_keeps_wall_film).
    bool wall_film = true;
};

inline const ParamTable<CouplingParams>& coupling_keys() {
    using T = CouplingParams;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(boolean_key<T>("coupling", "two_way", member(&T::two_way),
                                   "the fluid's forces act back on elastic and rigid objects (docs/coupling.md)"));
        t.push_back(boolean_key<T>("coupling", "correction", member(&T::correction),
                                   "the velocity-position correction against elastic and rigid objects"));
        t.push_back(number_key<T>("coupling", "slip", member(&T::slip), ParamRange{0, 1, false, false}, "",
                                  "the correction's tangential rule: 1 free slip, 0 no slip"));
        t.push_back(boolean_key<T>("coupling", "predict_solids", member(&T::predict_solids),
                                   "PCISPH meets the objects where the step will take them, not where they start it"));
        t.push_back(boolean_key<T>("coupling", "strong", member(&T::strong),
                                   "rigid and elastic objects answer the fluid's pressure inside the PCISPH iterations (with predict_solids)"));
        t.push_back(boolean_key<T>("coupling", "surface_inset", member(&T::surface_inset),
                                   "rigid and elastic objects' surface particles sit inside the face by the walls' gap, so fluid rests at the face"));
        t.push_back(boolean_key<T>("coupling", "wall_film", member(&T::wall_film),
                                   "with fluid, moving objects stop a fluid layer (1.5 r0) short of the walls and static boxes, so fluid caught there is not squeezed"));
        return t;
    }();
    return table;
}

}  // namespace mw
