// Particle type codes, the same everywhere in the project (store, VTU output, docs).
#pragma once
#include <cstdint>

namespace mw {
enum ParticleType : std::uint8_t {
    kFluid = 0,           // PCISPH fluid particle (FP)
    kStaticBoundary = 1,  // Akinci particle of a wall or static box; never moves
    kSurfaceBoundary = 2, // SBP: on a solid's surface
    kInnerBoundary = 3,   // IBP: lattice vertex inside a solid
    kGeometry = 4,        // GP: a vertex of a solid's mesh (rendering only, not in the fluid's sums)
    // An emitter's fluid particle not emitted yet (emitter.hpp): held in the store from the start
    // so that emitting allocates nothing; in no sum, never written to frames.
    kPending = 5,
};
inline const char* particle_type_name(int type) {
    switch (type) {
        case kFluid: return "fluid";
        case kStaticBoundary: return "static_boundary";
        case kSurfaceBoundary: return "sbp";
        case kInnerBoundary: return "ibp";
        case kGeometry: return "gp";
        case kPending: return "pending";
    }
    return "unknown";
}
constexpr int kParticleTypeCount = 6;
}  // namespace mw
