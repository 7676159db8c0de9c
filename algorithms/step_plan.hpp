// The time step, stage by stage, in the order of the method (docs/method.md, "One time step").
// Host-only and backend-free: `meltwater info`, the stats.csv columns and the docs' stage table
// (docs/architecture.md, checked by tests/cli) are read from this table. A module binds its functions
// to these names (algorithms/module.hpp); a scene runs the stages some module bound, in this order.
#pragma once
#include <cstddef>
#include <cstring>

namespace mw {

struct StageInfo {
    const char* name;    // the stats.csv column is ms_<name>
    const char* module;  // who binds it (algorithms/)
    const char* runs;    // when a scene runs it
    const char* does;    // one line: what it computes
};

inline constexpr StageInfo kStepStages[] = {
    {"neighbors", "neighbor_search, solid_correction, melting", "always",
     "sorts the moving particles by cell and permutes every field; neighbour lists (OpenMP); which fluid is near "
     "a moving solid; the melting lattices' faces"},
    {"solid_volumes", "boundary_volumes, solids, coupling", "fluid and moving solids",
     "Akinci volumes of the moving solids' boundary particles; where the solids will be at the step's end; the rigid "
     "and elastic objects' answer inside PCISPH (coupling.strong)"},
    {"viscosity", "fluid", "fluid with viscosity or wall friction",
     "gravity, viscosity (Eq. 4, mirrored across the domain walls) and wall friction (Eq. 8)"},
    {"interface_tension", "interface_tension", "fluid and an object with interface tension",
     "Eq. 9: fluid drawn toward the objects' surface particles"},
    {"pcisph", "fluid", "fluid",
     "predict, density, pressure, pressure force until the density error is below eta; a failed step is halved (CFL "
     "mode)"},
    {"heat", "heat", "heat.enabled", "conduction among the fluid and the moving solids, in explicit sub-steps"},
    {"coupling", "coupling", "fluid and moving solids, coupling.two_way",
     "the fluid's forces on the solids' boundary particles, onto their inner particles"},
    {"pressure_sensors", "pressure_sensors", "fluid and pressure_sensors",
     "the fluid's normal load on each sensor's patch of wall, over its area, for stats.csv"},
    {"lsm", "solids", "moving solids",
     "lattice shape matching of the inner particles, then the mesh vertices and surface particles"},
    {"integrate", "fluid", "fluid", "symplectic Euler, then the walls' velocity-position correction"},
    {"solid_contact", "solid_correction", "fluid and moving solids, coupling.correction",
     "the velocity-position correction against the moving solids' surface particles"},
    {"melting", "melting", "an object with a melting_point",
     "latent heat at the melting point; melted surface particles become fluid"},
    {"emit", "emitters", "an emitter", "the layers due by the step's end leave their discs as fluid"},
    {"statistics", "statistics", "always", "the fluid's and the solids' kinetic energy and top speed, for stats.csv"},
};
inline constexpr std::size_t kStageCount = sizeof kStepStages / sizeof kStepStages[0];

// The index of `name` in kStepStages, or kStageCount.
inline std::size_t stage_index(const char* name) {
    for (std::size_t k = 0; k < kStageCount; ++k)
        if (std::strcmp(kStepStages[k].name, name) == 0) return k;
    return kStageCount;
}

}  // namespace mw
