// The boundary's parameters: the domain walls and the walls' velocity-position correction
// (wall_correction.hpp), scene section `boundary`. Host-only.
#pragma once
#include <vector>

#include "algorithms/wall_contact.hpp"
#include "simulation/parameters.hpp"

namespace mw {

struct BoundaryParams {
    // Whether the domain's faces are lined with static wall particles: then they are free-slip
    // walls, and Eq. 4 next to them sums over the fluid's mirror images too. The domain's top is
    // closed like its other faces.
    bool walls = true;
    // How far outside the faces the walls' first particle layer lies (sampling/wall_gap.hpp), m;
    // negative: not given. The scene builder sets it from the walls it samples.
    Real wall_gap = -1;
    // The velocity-position correction against the domain walls, the static boxes and static mesh
    // objects (wall_contact.hpp): the paper's method, on unless a scene turns it off.
    bool correction = true;
    // The static boxes (their particles are in the setup's lists) and the static mesh objects'
    // signed distance grids, each object's values one after another in static_object_distances
    // (ContactField::field.first), for that correction. Set by the scene builder.
    std::vector<StaticBoxFaces> static_boxes;
    std::vector<ContactField> static_objects;
    std::vector<Real> static_object_distances;
};

inline const ParamTable<BoundaryParams>& boundary_keys() {
    using T = BoundaryParams;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(boolean_key<T>("boundary", "walls", member(&T::walls),
                                   "line the domain's faces, its top included, with static boundary particles; false "
                                   "leaves it open (fluid that leaves is lost)"));
        t.push_back(boolean_key<T>("boundary", "correction", member(&T::correction),
                                   "the velocity-position correction against the walls, static boxes and static "
                                   "objects (docs/solver.md)"));
        return t;
    }();
    return table;
}

}  // namespace mw
