// Fluid particles whose centres lie inside a moving 2D object's outline as it stands now: the
// penetrations the paper's 2D figures (Figs. 13-15) draw in red, counted at every frame of a run
// (summary.json, "fluid_inside_objects") and from Python (Simulation.fluid_inside_objects).
#pragma once
#include <vector>

#include "simulation/simulation.hpp"

namespace mw {

// Whether `solid` is a moving 2D object (its mesh an outline over its GPs).
bool has_moving_outline(const SolidSetup& solid);

// Per solid of `solids` (in order): how many fluid particles of `p` lie inside its outline, from
// its GPs' positions in `p`, a hollow object's closed cavity included (fluid there came through
// its wall); -1 for a solid that is not a moving outline.
std::vector<long> fluid_inside_outlines(const std::vector<SolidSetup>& solids, const HostParticles& p);

}  // namespace mw
