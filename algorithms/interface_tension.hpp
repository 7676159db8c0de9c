// Interface tension between fluid and moving solids (the paper's Eq. 9, after [IUD10]; docs/method.md,
// "Non-pressure forces"): a fluid particle i within h of a surface particle s (SBP) of an object whose
// `interface_tension` η_s is not 0 is drawn toward it,
//
//   F_{i<-s} = -η_s m_i ψ_s W(x_is, h) x_is / |x_is|,   ψ_s = ρ0 V_s,  x_is = x_i - x_s,
//
// a non-pressure force, from the positions at the start of the step (like viscosity), with x_s
// the SBP's face point (solid_face.hpp) over the pairs within h of the SBP itself. A melting
// object's surface particles are its exposed lattice vertices (melting.hpp): x_s is then the
// vertex's cell face, r0/2 in front of it along its normal (melting_faces.hpp), or the vertex
// where it has no outside. Its
// reaction F_{s<-i} = -F_{i<-s} goes back to the object with the other coupling forces
// (coupling.hpp), over the same pairs: every pair within h, which the 27 cells around either
// particle hold, so the pair's two forces cancel to rounding.
//
// Units: η is m⁴ kg⁻¹ s⁻² (F in N). A fluid particle by a flat surface is drawn toward it at
// about η ρ0 Σ_s V_s W_is, which does not depend on r0 at a fixed h / r0. Measured
// (tests/core/test_interface_tension.cpp, r0 = 0.02 m, h = 2 r0): one fluid layer 1.05 r0 under a
// plate hangs whole at η = 0.2, in part at 0.1-0.15, not at 0.08 and less.
// The paper gives no value of η.
#pragma once
#include <cstdint>

#include "algorithms/boundary_volumes.hpp"
#include "algorithms/fluid.hpp"
#include "algorithms/melting_faces.hpp"
#include "algorithms/module.hpp"
#include "algorithms/particle_types.hpp"
#include "algorithms/solid_bodies.hpp"
#include "algorithms/solid_face.hpp"

MW_BACKEND_BEGIN

// What the tension reads: the moving solids' particles and each SBP's η.
struct TensionData {
    View<const std::uint8_t> type;  // store fields
    View<const std::int32_t> solid_slot;
    const Real* sbp_eta = nullptr;  // η per SBP index; null: none on any SBP
    SbpFaces faces;                 // where each SBP meets the fluid (solid_face.hpp)
    const Real* lattice_eta = nullptr;  // η per IBP slot, a melting object's; null: none
    const Vec3* lattice_normal = nullptr;  // its exposed vertices' normals (melting_faces.hpp)
    Real lattice_inset = 0;                // m: their faces lie this far in front of them (r0/2)
    std::uint32_t ibp_count = 0;    // SBP k has solid slot ibp_count + k
};

// a_i += Σ_s -η_s ψ_s W(x_is) x_is / |x_is| (F / m_i) over the SBPs around fluid particle i.
// `accumulate`: add to what the viscosity stage wrote; otherwise start from gravity.
template <class Kernel>
void add_interface_tension(const DeviceContext& device, GridView grid, std::size_t fluid_count, View<const Vec3> position,
                           View<const Real> boundary_volume, View<Vec3> acceleration, const TensionData t,
                           Kernel kernel, Real rest_density, Vec3 gravity, bool accumulate) {
    parallel_for(device, "interface_tension", fluid_count, [=] MW_HD(std::size_t i) {
        const Vec3 xi = position[i];
        Vec3 sum{0, 0, 0};
        grid.for_each_solid(xi, [&](std::uint32_t b) {
            if (t.type[b] != kSurfaceBoundary) return;
            // The pair: within h of the SBP (as the coupling's reaction pairs them).
            if (!(norm2(xi - position[b]) < kernel.h * kernel.h)) return;
            // The pull: toward an SBP's face point; for a melting lattice's exposed vertex (an IBP
            // slot, melting.hpp), toward its cell's face, r0/2 in front of it (on the vertex where
            // it has no outside), where the correction meets it too.
            const std::uint32_t slot = static_cast<std::uint32_t>(t.solid_slot[b]);
            Real eta = 0;
            Vec3 toward = position[b];
            if (slot >= t.ibp_count) {
                if (!t.sbp_eta) return;
                eta = t.sbp_eta[slot - t.ibp_count];
                toward = t.faces.at(position[b], slot - t.ibp_count);
            } else if (t.lattice_eta) {
                eta = t.lattice_eta[slot];
                toward = position[b] + t.lattice_inset * t.lattice_normal[slot];
            }
            if (!(eta > Real(0))) return;
            const Vec3 r = xi - toward;
            const Real r2 = norm2(r);
            const Real w = kernel.W_r2(r2);
            if (!(w > Real(0)) || !(r2 > Real(0))) return;
            sum += (eta * boundary_volume[b] * w / std::sqrt(r2)) * r;
        });
        const Vec3 a = -rest_density * sum;
        acceleration[i] = accumulate ? acceleration[i] + a : gravity + a;
    });
}

// The interface tension module (stage "interface_tension"): with fluid and an object whose
// interface_tension is not 0. It adds to the fluid's non-pressure forces; its reaction on the
// objects is the coupling's (coupling.hpp).
template <class Kernel>
class InterfaceTension final : public Module {
   public:
    InterfaceTension(SimulationState<Kernel>& state, const BoundaryVolumes<Kernel>& volumes, Fluid<Kernel>& fluid,
                     const SolidBodies& solids)
        : state_(state), volumes_(volumes), fluid_(fluid), solids_(solids),
          active_(state.has_fluid && solids.active() && solids.has_tension()) {}

    // Whether the scene needs it (the fluid then keeps a non-pressure field for it).
    static bool needed(bool has_fluid, const SolidBodies& solids) {
        return has_fluid && solids.active() && solids.has_tension();
    }

    void bind(StepPlan& plan) override {
        if (active_) plan.bind("interface_tension", [this](StepContext& step) { apply(step); });
    }

    void apply(StepContext& step) {
        TensionData t;
        t.type = state_.store.type.cview();
        t.solid_slot = solids_.solid_slot_view();
        t.sbp_eta = solids_.sbp_eta();
        t.lattice_eta = solids_.lattice_eta();
        t.lattice_normal = solids_.lattice_normals();
        t.lattice_inset = lattice_face_offset(state_.params.fluid.spacing);
        t.faces = solids_.sbp_faces();
        t.ibp_count = static_cast<std::uint32_t>(solids_.ibp_count());
        add_interface_tension(state_.device, step.neighbors.grid, step.ranges.fluid_end, state_.store.position.cview(),
                              volumes_.volumes(), fluid_.nonpressure(), t, state_.fluid.kernel,
                              state_.fluid.rest_density, state_.fluid.gravity, fluid_.has_viscosity());
        step.nonpressure = fluid_.nonpressure().data();
    }

   private:
    SimulationState<Kernel>& state_;
    const BoundaryVolumes<Kernel>& volumes_;
    Fluid<Kernel>& fluid_;
    const SolidBodies& solids_;
    bool active_ = false;
};

MW_BACKEND_END
