// Where the domain walls' first particle layer goes so that fluid touching a wall starts at rest.
#pragma once
#include "algorithms/sph_kernels.hpp"

namespace mw {

// The distance outside the domain faces, in metres, at which the first Akinci layer of the domain
// walls (then `layers` layers `boundary_spacing` apart, each a square grid of that spacing) gives a
// fluid layer r0/2 inside a face exactly the rest density, for the solver's kernel (`kernel`) of
// support h and its fluid mass (a full lattice at spacing r0 has the rest density). Fluid blocks
// fill the domain from r0/2 inside its faces, so they then start at rest next to the walls.
//
// Why it is computed and not a constant: a wall layer stands for the fluid missing beyond the
// face, and how much of it one sheet of particles represents depends on h/r0, on the spacing and
// on the number of layers. A constant 0.6 r0 is right only for h = 2 r0 and one layer: at the
// paper's h = 2.5 r0 it leaves the fluid next to a face 9% over its rest density, 15% along an
// edge and 21% in a corner, and a resting column blows up in its first step at any Δt
// (docs/solver.md).
//
// Computed for a flat face: the first fluid layer's density, from the half-lattice of fluid and
// the infinite wall sheets (their Akinci volumes 1 / Σ_k W over all the layers), falls
// monotonically as the walls move out; bisection finds where it equals the rest density. Throws
// InputError if no distance in [0, h + r0] does: not the case for h in (r0, 4 r0] but for h within
// about 1e-6 of r0, where W(r0) no longer registers in the sums.
Real rest_density_wall_gap(Real r0, Real h, Real boundary_spacing, int layers, KernelKind kernel, int dimensions = 3);

}  // namespace mw
