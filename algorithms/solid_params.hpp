// A solid object's parameters (solid_bodies.hpp, heat.hpp, melting.hpp): its kind, material and
// shape matching, scene keys `objects[i]` and `objects[i].lsm`. Host-only.
#pragma once
#include <cmath>
#include <limits>

#include "simulation/parameters.hpp"

namespace mw {

// Cloth (docs/cloth.md): one layer of particles on an open sheet mesh, shape-matched over the
// k-rings of its vertices, met by the fluid from both sides. Rod (docs/rods.md): one line of
// particles, shape-matched over runs of nodes along it, met by the fluid from every side.
enum class SolidKind { kElastic, kRigid, kStatic, kCloth, kRod };

// Cloth and rods: shape-matched over a graph of nodes (the mesh's edges, the line's links) rather
// than a lattice; every node is a particle the fluid meets, and a node answers the fluid's pressure
// inside the solve under coupling.strong (docs/cloth.md, "Light cloth").
inline bool is_thin(SolidKind kind) { return kind == SolidKind::kCloth || kind == SolidKind::kRod; }

struct SolidParams {
    SolidKind kind = SolidKind::kElastic;
    Real density = 1000;        // kg/m3; an inner particle's mass is density r0^3
    int region_half_width = 2;  // w: a region holds the IBPs within w lattice links (elastic)
    Real stiffness = 1;         // alpha in (0, 1]
    Real damping = 0;           // 1/s: rate at which non-rigid velocity in each region decays
    Real body_damping = 5;      // 1/s: rate at which velocity apart from the whole body's rigid motion decays
    Real wall_friction = 0.2;   // [0, 1]: share of tangential velocity removed per wall contact
    Real interface_tension = 0;  // eta of Eq. 9 between its SBPs and the fluid, m4 kg-1 s-2 (interface_tension.hpp)
    Real thermal_diffusivity = Real(1.43e-7);  // alpha, m2/s, with heat conduction (heat.hpp)
    Real heat_capacity = Real(4.18e6);         // rho c, J/(m3 K), with heat conduction
    // Melting (melting.hpp, elastic objects with heat conduction only): the object's lattice is all
    // of it (no GPs, no mesh SBPs; a lattice vertex missing one of its 26 one-ring neighbours has
    // the SBP type), and an SBP at or above the melting point that has absorbed its latent heat
    // becomes fluid. Infinite: the object never melts.
    Real melting_point = std::numeric_limits<Real>::infinity();  // C
    Real latent_heat = 0;                                        // J/kg
    bool melts() const { return melting_point < std::numeric_limits<Real>::infinity(); }
};

inline const ParamTable<SolidParams>& solid_keys() {
    using T = SolidParams;
    static const ParamTable<T> table = [] {
        ParamTable<T> t;
        t.push_back(choice_key<T, SolidKind>(
            "objects[]", "kind", member(&T::kind),
            {{"elastic", SolidKind::kElastic}, {"rigid", SolidKind::kRigid}, {"static", SolidKind::kStatic},
             {"cloth", SolidKind::kCloth}, {"rod", SolidKind::kRod}},
            "elastic (LSM regions), rigid (one region), static (a fixed boundary), cloth (one layer on an open "
            "sheet, docs/cloth.md) or rod (one line of particles, docs/rods.md)"));
        t.push_back(number_key<T>("objects[]", "density", member(&T::density), ParamRange::positive(), "kg/m3",
                                  "the solid's density"));
        t.push_back(number_key<T>("objects[]", "interface_tension", member(&T::interface_tension),
                                  ParamRange::non_negative(), "m4/(kg s2)",
                                  "eta of Eq. 9: fluid drawn to its surface (moving objects, melting ones included)"));
        t.push_back(number_key<T>("objects[]", "thermal_diffusivity", member(&T::thermal_diffusivity),
                                  ParamRange::non_negative(), "m2/s", "alpha, with heat.enabled")
                        .derive_default([](const ResolvedKeys& r) { return *r.find("fluid.thermal_diffusivity"); },
                                        "fluid.thermal_diffusivity"));
        t.push_back(number_key<T>("objects[]", "heat_capacity", member(&T::heat_capacity), ParamRange::positive(),
                                  "J/(m3 K)", "rho c, with heat.enabled")
                        .derive_default([](const ResolvedKeys& r) { return *r.find("fluid.heat_capacity"); },
                                        "fluid.heat_capacity"));
        ParamKey<T> melting;
        melting.section = "objects[]";
        melting.name = "melting_point";
        melting.type = ParamType::kOptionalNumber;
        melting.unit = "C";
        melting.doc = "melts from its surface at this temperature (elastic objects, heat.enabled; docs/melting.md); "
                      "null: never";
        melting.range = ParamRange::celsius();
        melting.get = [](const T& s) { return s.melts() ? ParamValue::of(shortest_decimal(s.melting_point)) : ParamValue::null(); };
        melting.set = [](T& s, const ParamValue& v) {
            s.melting_point = v.kind == ParamValue::Kind::kNull ? std::numeric_limits<Real>::infinity() : Real(v.number);
        };
        t.push_back(melting);
        t.push_back(number_key<T>("objects[]", "latent_heat", member(&T::latent_heat), ParamRange::non_negative(),
                                  "J/kg", "heat absorbed at the melting point before a particle melts"));
        t.push_back(integer_key<T>("objects[].lsm", "w", member(&T::region_half_width), 1, 8,
                                   "region half-width: a region holds the lattice particles within w links (cloth: the mesh's w-ring)"));
        t.push_back(number_key<T>("objects[].lsm", "alpha", member(&T::stiffness), ParamRange{0, 1, true, false}, "",
                                  "stiffness: the share of the way to the goal taken each step"));
        t.push_back(number_key<T>("objects[].lsm", "damping", member(&T::damping), ParamRange::non_negative(), "1/s",
                                  "rate at which each region's non-rigid velocity decays"));
        t.push_back(number_key<T>("objects[].lsm", "body_damping", member(&T::body_damping), ParamRange::non_negative(),
                                  "1/s", "rate at which velocity apart from the whole body's rigid motion decays "
                                  "(bending; docs/lsm.md)"));
        t.push_back(number_key<T>("objects[].lsm", "wall_friction", member(&T::wall_friction),
                                  ParamRange{0, 1, false, false}, "",
                                  "share of tangential velocity a domain wall removes on contact"));
        return t;
    }();
    return table;
}

}  // namespace mw
