// Melting, the second half (docs/method.md, "Melting"; docs/melting.md): phase change, outside in.
// Heat conduction (heat.hpp) brings the temperatures; this stage, once a step after the fluid's
// integration, turns a melting object's surface particles into fluid.
//
// A melting object is its lattice (lsm_regions.hpp): every vertex is an LSM particle (an IBP
// slot), and a vertex missing any of its 26 one-ring neighbours has the SBP type. Each step, for
// every vertex still in its object:
// - Latent heat. Its temperature stops at the melting point T_m: heat that would raise it past
//   T_m is absorbed instead, kept per particle as `latent_heat` in kelvins of the object's own
//   heat capacity (L ρ / C for a latent heat L per kg), so that Σ M (T + latent) is the heat
//   content heat.hpp conserves. Below T_m an absorbed store flows back into T first (refreezing).
// - Phase change. An SBP at T_m whose store has reached L ρ / C melts: it becomes a fluid particle
//   (type, no slot, no object, the fluid's rest density as its last density) with the velocity
//   it had (two-way, plus the correction's impulse of the step as J / m, melting_faces.hpp), and
//   what it absorbed past the latent heat returns to its temperature (scaled by the object's heat
//   capacity over the fluid's, so that it stays the same heat per volume). Only
//   SBPs melt, so an object melts from the outside in.
// - Its neighbours lose it: a vertex left with fewer than 26 one-ring neighbours becomes an SBP,
//   and the object's regions are rebuilt over the vertices left (rebuild_elastic_object_regions;
//   a region only shrinks, in place). The melted particle's slot is marked kMeltedSlot in the slot
//   map, which every per-slot kernel skips.
// The step's melt flags are a reduction read back (one synchronisation a step, in scenes with a
// melting object); on a step where something melted, the exposure, the phase change and the
// regions' rebuild run in kernels (melting_regions.hpp), and a second reduction reads back how
// many were exposed.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "algorithms/lsm_regions.hpp"
#include "algorithms/melting_faces.hpp"
#include "algorithms/melting_regions.hpp"
#include "algorithms/particle_store.hpp"
#include "algorithms/particle_types.hpp"
#include "simulation/simulation.hpp"
#include "algorithms/solid_bodies.hpp"
#include "backend/backend.hpp"
#include "backend/reduce_ops.hpp"

MW_BACKEND_BEGIN

// Per object (indexed like SimulationSetup::solids): where it melts and its latent heat.
struct MeltingPoint {
    std::uint8_t melts = 0;
    Real temperature = 0;    // T_m, °C
    Real latent_kelvin = 0;  // L ρ / C, K
    Real capacity_ratio = 1; // C / C_fluid: turns a kelvin of the object's heat capacity into the fluid's
};

// What the latent-heat kernel reads and writes.
struct MeltingData {
    const std::uint32_t* store_of_slot = nullptr;
    const std::int32_t* slot_object = nullptr;
    const MeltingPoint* objects = nullptr;
    const std::uint8_t* type = nullptr;  // store fields
    Real* temperature = nullptr;
    Real* latent = nullptr;
    std::uint8_t* melts = nullptr;  // per IBP slot: 1 where it melts this step
};

// Per IBP slot of a melting object still in it: the latent-heat exchange at T_m, and whether the
// particle melts now (see the top of the file).
inline void exchange_latent_heat(const DeviceContext& device, std::size_t ibp_count, const MeltingData d) {
    parallel_for(device, "melting_latent_heat", ibp_count, [=] MW_HD(std::size_t s) {
        d.melts[s] = 0;
        const std::uint32_t i = d.store_of_slot[s];
        if (i == kMeltedSlot) return;
        const MeltingPoint point = d.objects[d.slot_object[s]];
        if (!point.melts) return;
        Real T = d.temperature[i], stored = d.latent[i];
        if (T > point.temperature) {
            stored += T - point.temperature;
            T = point.temperature;
        } else if (stored > Real(0)) {
            const Real released = stored < point.temperature - T ? stored : point.temperature - T;
            stored -= released;
            T += released;
        }
        if (d.type[i] == kSurfaceBoundary && T >= point.temperature && stored >= point.latent_kelvin) {
            // The heat past the latent heat stays heat as the particle takes the fluid's capacity.
            T += (stored - point.latent_kelvin) * point.capacity_ratio;
            stored = 0;
            d.melts[s] = 1;
        }
        d.temperature[i] = T;
        d.latent[i] = stored;
    });
}

// What one step's phase change did.
struct PhaseChangeCounts {
    long melted = 0;   // SBPs that became fluid
    long exposed = 0;  // IBPs that became SBPs
};

// The melting module (stage "melting", with an object that has a melting_point): its buffers, and
// the host's record of which lattice vertices are left.
class PhaseChange final : public Module {
   public:
    // `solids` initialised, and the heat's store field `temperature` registered. Registers the
    // store field `latent_heat` (K, 0 to start). Throws InputError for a melting object that is not
    // elastic, or melting without heat conduction.
    PhaseChange(const DeviceContext& device, const SimulationSetup& setup, ParticleStore& store, SolidBodies& solids,
                ParticleCounts& counts, Real rest_density, Real fluid_mass)
        : device_(device), store_(store), solids_(solids), counts_(counts), rest_density_(rest_density),
          fluid_mass_(fluid_mass) {
        std::vector<MeltingPoint> points(setup.solids.size());
        bool any = false;
        for (std::size_t o = 0; o < setup.solids.size(); ++o) {
            const SolidSetup& solid = setup.solids[o];
            if (!solid.melts()) continue;
            if (solid.kind != SolidKind::kElastic)
                throw InputError("simulation setup: solid \"" + solid.name + "\" melts; only elastic objects can");
            if (!setup.params.heat.enabled)
                throw InputError("simulation setup: solid \"" + solid.name + "\" melts; melting needs heat conduction");
            if (!std::isfinite(double(solid.melting_point)) || !(solid.latent_heat >= 0) ||
                !std::isfinite(double(solid.latent_heat)))
                throw InputError("simulation setup: solid \"" + solid.name +
                                 "\" needs a finite melting point and a finite latent heat >= 0");
            if (!solid.gp.empty() || !solid.sbp.empty())
                throw InputError("simulation setup: solid \"" + solid.name +
                                 "\" melts, so it must be its lattice alone (no mesh vertices or surface samples)");
            points[o].melts = 1;
            points[o].temperature = solid.melting_point;
            points[o].latent_kelvin = static_cast<Real>(double(solid.latent_heat) * double(solid.density) /
                                                        double(solid.heat_capacity));
            points[o].capacity_ratio =
                static_cast<Real>(double(solid.heat_capacity) / double(setup.params.heat.fluid_capacity));
            any = true;
        }
        if (!any) return;
        temperature_ = store.find<Real>("temperature");
        if (!temperature_) throw InputError("simulation setup: melting needs heat conduction");
        ibp_count_ = solids.ibp_count();
        full_ring_ = full_one_ring(setup.params.dimensions);
        sheet_below_ = static_cast<Real>(lattice_sheet_threshold(full_ring_) * double(setup.params.fluid.spacing));
        points_.upload(points);
        latent_ = &store.add<Real>("latent_heat", FieldLife::kPersistent);
        latent_->fill(Real(0));
        melts_.assign(std::max<std::size_t>(1, ibp_count_), 0);
        // The lattices on the device: each one's grid of cells, each vertex's grid coordinates,
        // and the per-step flags, all sized here so that a step allocates nothing.
        std::vector<std::int32_t> cell_slot, slot_coord(3 * ibp_count_, 0);
        // The melting objects' particles must carry the SBP type exactly where a one-ring
        // neighbour is missing: that is what decides which may melt.
        const std::vector<std::uint8_t>& type_of_scene = setup.type;
        const int full_ring = full_ring_;
        for (const auto& m : solids.melting_lattices()) {
            lattice_particles_ += long(m.lattice.size());
            if (m.region_half_width > kMeltingLargestHalfWidth)
                throw InputError("simulation setup: solid \"" + setup.solids[m.object].name + "\" melts with regions of half-width " +
                                 std::to_string(m.region_half_width) + "; at most " +
                                 std::to_string(kMeltingLargestHalfWidth));
            grids_.push_back(melting_grid(m.lattice, m.base, m.region_half_width, full_ring, cell_slot, slot_coord));
            const std::vector<std::uint8_t> counts = lattice_one_ring_counts(m.lattice);
            const SolidSetup& solid = setup.solids[m.object];
            for (std::size_t k = 0; k < m.lattice.size(); ++k) {
                const std::uint8_t expected = counts[k] < full_ring ? kSurfaceBoundary : kInnerBoundary;
                if (type_of_scene[solid.ibp[k]] != expected)
                    throw InputError("simulation setup: solid \"" + solid.name +
                                     "\" melts; a lattice vertex with " + std::to_string(int(counts[k])) +
                                     " of its " + std::to_string(full_ring) + " one-ring neighbours must have the " +
                                     particle_type_name(expected) +
                                     " type");
            }
        }
        cell_slot_.upload(cell_slot);
        slot_coord_.upload(slot_coord);
        reach_.assign(cell_slot.size(), 0);
        reach_next_.assign(cell_slot.size(), 0);
        exposed_.assign(std::max<std::size_t>(1, ibp_count_), 0);
        // The reductions' workspace, before the first step.
        count_melting();
        count_exposed();
    }

    bool active() const { return latent_ != nullptr; }

    void bind(StepPlan& plan) override {
        if (!active()) return;
        if (solids_.lattice_faces().normal) plan.bind("neighbors", [this](StepContext&) { find_faces(); });
        plan.bind("melting", [this](StepContext&) { melt(); });
    }
    // After the sort: the exposed vertices' normals for the correction, and their contact masses
    // where the regions changed since they were last found (melting_faces.hpp).
    void find_faces() {
        const MeltingRegionArrays r = solids_.melting_region_arrays();
        LatticeFaceInputs in;
        in.cell_slot = cell_slot_.cview().data();
        in.slot_coord = slot_coord_.cview().data();
        in.store_of_slot = solids_.slot_map().data();
        in.type = store_.type.cview().data();
        in.position = store_.position.cview().data();
        in.pinned = solids_.pinned_slots().data();
        in.regions_begin = r.regions_begin;
        in.regions_end = r.regions_end;
        in.member_index = r.member_index;
        in.region_mass = r.region_mass;
        in.sheet_below = sheet_below_;
        const LatticeFaceArrays out = solids_.lattice_faces();
        for (const MeltingGrid& g : grids_) melting_lattice_normals(device_, g, in, out);
        if (out.inverse_mass && contact_masses_stale_)
            for (const MeltingGrid& g : grids_) melting_lattice_contact_masses(device_, g, in, out);
        contact_masses_stale_ = false;
    }
    // Latent heat at the melting point, then the melting objects' SBPs that melt become fluid (the
    // next step's sort moves them to the fluid's range), the IBPs they leave exposed become SBPs,
    // and the regions are rebuilt.
    void melt() {
        const PhaseChangeCounts changed = step(store_, solids_, *temperature_, rest_density_);
        counts_.by_type[kFluid] += changed.melted;
        counts_.by_type[kSurfaceBoundary] += changed.exposed - changed.melted;
        counts_.by_type[kInnerBoundary] -= changed.exposed;
    }
    void report_columns(std::vector<std::string>& names) const override {
        if (active()) names.push_back("melted");
    }
    void report(std::vector<double>& values) const override {
        if (active()) values.push_back(double(melted_total_));
    }
    View<const Real> latent() const { return latent_ ? latent_->cview() : View<const Real>{}; }
    // Particles melted since the scene started.
    long melted_total() const { return melted_total_; }
    // Particles that may melt: every lattice vertex of a melting object (each may become fluid).
    long lattice_particles() const { return lattice_particles_; }

    // One step (the slot map current, this step's temperatures in `temperature`).
    PhaseChangeCounts step(ParticleStore& store, SolidBodies& solids, DeviceArray<Real>& temperature,
                           Real rest_density) {
        MeltingData d;
        d.store_of_slot = solids.slot_map().data();
        d.slot_object = solids.slot_objects().data();
        d.objects = points_.view().data();
        d.type = store.type.cview().data();
        d.temperature = temperature.view().data();
        d.latent = latent_->view().data();
        d.melts = melts_.view().data();
        exchange_latent_heat(device_, ibp_count_, d);
        PhaseChangeCounts counts;
        counts.melted = count_melting();
        if (counts.melted == 0) return counts;
        // Something melts: who is exposed, the store's types, the regions left.
        MeltingLatticeData l;
        l.cell_slot = cell_slot_.cview().data();
        l.slot_coord = slot_coord_.cview().data();
        l.melts = melts_.cview().data();
        l.exposed = exposed_.view().data();
        l.reach = reach_.view().data();
        l.reach_next = reach_next_.view().data();
        l.regions = solids.melting_region_arrays();
        PhaseChangeData& p = l.particles;
        p.store_of_slot = solids.slot_map().data();
        p.type = store.type.view().data();
        p.solid_slot = solids.solid_slot_field().view().data();
        p.object = store.object.view().data();
        p.density = store.density.view().data();
        p.rest_density = rest_density;
        p.lattice_impulse = solids.lattice_faces().impulse;
        p.velocity = store.velocity.view().data();
        p.inverse_fluid_mass = Real(1) / fluid_mass_;
        for (const MeltingGrid& g : grids_) update_melting_lattice(device_, g, l);
        contact_masses_stale_ = true;
        melted_total_ += counts.melted;
        counts.exposed = count_exposed();
        return counts;
    }

    // After a checkpoint's store has loaded: the slots left are those some particle still holds;
    // the regions are rebuilt over them and the others marked melted in the slot map (which the
    // next step's sort fills for the rest).
    void load(const StateArchive&) override { load(store_, solids_); }
    void load(const ParticleStore& store, SolidBodies& solids) {
        if (!active()) return;
        const std::vector<std::int32_t> slot = solids.solid_slot_field().to_host();
        std::vector<std::uint8_t> held(ibp_count_, 0);
        for (std::size_t i = 0; i < store.moving_count(); ++i)
            if (slot[i] >= 0 && std::size_t(slot[i]) < ibp_count_) held[std::size_t(slot[i])] = 1;
        std::vector<std::uint8_t> alive(ibp_count_, 1);
        for (const auto& m : solids.melting_lattices())
            for (std::size_t k = 0; k < m.lattice.size(); ++k) alive[m.base + k] = held[m.base + k];
        melted_total_ = long(std::count(alive.begin(), alive.end(), std::uint8_t(0)));
        solids.rebuild_melting_regions(alive);
        solids.slot_map_fill(kMeltedSlot);
        solids.update_slot_map(store);
        contact_masses_stale_ = true;
    }

    std::size_t bytes() const override {
        return points_.bytes() + melts_.bytes() + exposed_.bytes() + cell_slot_.bytes() +
               slot_coord_.bytes() + reach_.bytes() + reach_next_.bytes();
    }

    // The number of slots flagged to melt this step (a reduction read back). Public only because
    // nvcc allows no device lambda in a private member function.
    long count_melting() {
        const std::uint8_t* melts = melts_.cview().data();
        return long(transform_reduce(device_, "melting_count", ibp_count_, std::uint32_t(0), SumOp{},
                                     [=] MW_HD(std::size_t s) { return std::uint32_t(melts[s]); }));
    }
    // The number of slots exposed this step (a reduction read back).
    long count_exposed() {
        const std::uint8_t* exposed = exposed_.cview().data();
        return long(transform_reduce(device_, "melting_exposed_count", ibp_count_, std::uint32_t(0), SumOp{},
                                     [=] MW_HD(std::size_t s) { return std::uint32_t(exposed[s]); }));
    }

   private:
    const DeviceContext& device_;
    ParticleStore& store_;
    SolidBodies& solids_;
    ParticleCounts& counts_;
    Real rest_density_ = 0;
    Real fluid_mass_ = 0;  // kg, a fluid particle's: what a melted vertex weighs
    DeviceArray<Real>* temperature_ = nullptr;  // the heat's store field
    std::size_t ibp_count_ = 0;
    DeviceArray<MeltingPoint> points_;         // per object
    DeviceArray<Real>* latent_ = nullptr;      // store field: heat absorbed at T_m, K
    DeviceArray<std::uint8_t> melts_;          // per IBP slot, this step's
    DeviceArray<std::uint8_t> exposed_;        // per IBP slot: exposed this step
    DeviceArray<std::int32_t> cell_slot_;      // per cell of the melting lattices' grids: its vertex's slot, -1 none
    DeviceArray<std::int32_t> slot_coord_;     // per IBP slot: its grid coordinates (3)
    DeviceArray<std::uint8_t> reach_, reach_next_;  // per cell: steps to a vertex gone this step
    long melted_total_ = 0;
    long lattice_particles_ = 0;               // of the melting objects, at the start
    int full_ring_ = 26;                       // a vertex's one-ring neighbours: 26, or 8 in 2D
    Real sheet_below_ = 0;                     // m: a vertex summing less is met from all round
    bool contact_masses_stale_ = true;         // the regions or the exposed vertices changed since find_faces
    std::vector<MeltingGrid> grids_;           // per melting object: its lattice's grid
};

MW_BACKEND_END
