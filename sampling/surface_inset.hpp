// How far each surface particle (SBP) of an elastic or rigid object sits inside its mesh's face
// (docs/coupling.md, "Where the fluid rests"). A domain wall's first layer lies the walls' gap
// outside its face (sampling/wall_gap.hpp), so that fluid rests at rest density r0/2 inside it; an
// object's SBPs set in by the same length give the fluid the same surface: without it the fluid
// r0/2 from the face reads 1.46 ρ0 and rests about one r0 off it, and a floating body rides that
// high. Host only, double precision.
#pragma once
#include <vector>

#include "sampling/mesh.hpp"
#include "sampling/surface_sampler.hpp"

namespace mw {

// Per SBP of `sbp` (sampled on `mesh`, oriented outward): `depth`, or half the mesh's thickness
// under it where that is less (the distance along -normal to the next face, so that the SBPs of
// a thin plate's two sides do not cross). For a closed mesh: an open one has no inside to set
// its SBPs into (the caller leaves them on it). depth >= 0.
std::vector<double> surface_insets(const TriangleMesh& mesh, const SurfaceParticles& sbp, double depth);

}  // namespace mw
