// The solids module: the moving solids of a simulation (elastic and rigid objects) on one backend,
// their LSM state, the stable slot of each solid particle, and the per-step work (docs/method.md,
// "Lattice shape matching"; stage "lsm").
//
// Slots: the particle store re-sorts particles every step, so every solid particle (IBP, SBP,
// GP) carries its fixed slot in a persistent store field `solid_slot` (-1 for others), and after
// each sort one kernel rebuilds store_of_slot[slot] = store index. All LSM arrays are indexed by
// slot; kernels read and write positions and velocities in the store through that map.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "algorithms/coupling.hpp"
#include "algorithms/lsm.hpp"
#include "algorithms/melting_faces.hpp"
#include "algorithms/module.hpp"
#include "algorithms/particle_store.hpp"
#include "algorithms/particle_types.hpp"
#include "algorithms/pcisph.hpp"
#include "algorithms/solid_collisions.hpp"
#include "algorithms/solid_contact.hpp"
#include "algorithms/solid_interpolation.hpp"
#include "algorithms/state_archive.hpp"

MW_BACKEND_BEGIN

// Rebuilds store_of_slot from the store's solid_slot field (particles [0, count)).
inline void build_slot_map(const DeviceContext& device, std::size_t count, View<const std::int32_t> solid_slot, View<std::uint32_t> store_of_slot) {
    parallel_for(device, "solid_slot_map", count, [=] MW_HD(std::size_t i) {
        const std::int32_t s = solid_slot[i];
        if (s >= 0) store_of_slot[static_cast<std::size_t>(s)] = static_cast<std::uint32_t>(i);
    });
}

inline SolidSummary summarize_solids(const DeviceContext& device, const LsmData d) {
    const MotionSummary m = transform_reduce(device,
        "solid_summary", d.ibp_count, MotionSummary{}, MotionSummaryOp{}, [=] MW_HD(std::size_t s) {
            const std::uint32_t i = d.store_of_slot[s];
            if (i == kMeltedSlot) return MotionSummary{};  // now fluid (melting.hpp)
            return particle_motion(d.position[i], d.velocity[i], d.mass[s], static_cast<std::uint32_t>(s));
        });
    return SolidSummary{m.kinetic_energy, m.max_speed2, m.first_bad};
}

class SolidBodies final : public Module {
   public:
    explicit SolidBodies(const DeviceContext& device) : device_(device) {}

    // Registers the slot field in `store` (already sized and filled in the order `order`, the
    // scene index of each store entry) and uploads the layout built from `setup`. Regions of more
    // than `serial_limit` members are summed in chunks (tests lower or raise it).
    void init(const SimulationSetup& setup, const std::vector<std::uint32_t>& order, ParticleStore& store,
              std::size_t serial_limit = kRegionSerialMembers) {
        LsmHostLayout L = build_lsm_layout(setup, serial_limit);
        ibp_count_ = L.ibp_count;
        sbp_count_ = L.sbp_count;
        gp_count_ = L.gp_count;
        if (ibp_count_ == 0) return;
        std::vector<std::int32_t> slot_of_scene(setup.position.size(), -1);
        for (std::size_t s = 0; s < L.scene_index.size(); ++s) {
            if (slot_of_scene[L.scene_index[s]] >= 0)
                throw InputError("simulation setup: a particle belongs to two solid objects");
            slot_of_scene[L.scene_index[s]] = static_cast<std::int32_t>(s);
        }
        std::vector<std::int32_t> slot(order.size());
        for (std::size_t k = 0; k < order.size(); ++k) {
            slot[k] = slot_of_scene[order[k]];
            if (slot[k] >= 0 && k >= store.moving_count())
                throw InputError("simulation setup: a particle of a moving solid has the static boundary type");
        }
        solid_slot_ = &store.add<std::int32_t>("solid_slot", FieldLife::kPersistent);
        solid_slot_->upload(slot);
        store_of_slot_.resize(L.slot_count());
        rest_.upload(L.ibp_rest);
        mass_.upload(L.ibp_mass);
        split_mass_.upload(L.ibp_split_mass);
        pinned_.upload(L.ibp_pinned);
        regions_begin_.upload(L.ibp_regions_begin);
        regions_end_.upload(L.ibp_regions_end);
        displacement_.assign(ibp_count_, Vec3{0, 0, 0});
        mean_rotation_.assign(ibp_count_, mat3_identity());
        region_offsets_.upload(L.region_offsets);
        region_end_.upload(L.region_end);
        member_index_.upload(L.member_index);
        region_mass_.upload(L.region_mass);
        region_c0_.upload(L.region_c0);
        region_A0_.upload(L.region_A0);
        region_inertia_inv_.upload(L.region_inertia_inv);
        region_object_.upload(L.region_object);
        region_chunks_.upload(L.region_chunks);
        chunk_begin_.upload(L.chunk_begin);
        chunk_region_.upload(L.chunk_region);
        chunk_sums_.resize(L.chunk_begin.size());
        const std::size_t regions = L.region_count();
        rotation_.assign(regions, quat_identity());
        rotation_matrix_.assign(regions, mat3_identity());
        mean_displacement_.assign(regions, Vec3{0, 0, 0});
        bool any_damping = false;
        for (const auto& o : L.objects) any_damping = any_damping || o.damping_rate > 0;
        if (any_damping) {
            region_velocity_.assign(regions, Vec3{0, 0, 0});
            region_omega_.assign(regions, Vec3{0, 0, 0});
        }
        objects_.upload(L.objects);
        has_rigid_ = has_body_answer_ = has_elastic_ = has_cloth_ = false;
        bool body_damping = false;
        for (const auto& o : L.objects) {
            has_cloth_ = has_cloth_ || o.nodal;
            has_rigid_ = has_rigid_ || o.rigid;
            has_body_answer_ = has_body_answer_ || o.body_answer;
            has_elastic_ = has_elastic_ || !o.rigid;
            body_damping = body_damping || o.body_damping_rate > Real(0);
        }
        body_motion_.assign(body_damping ? L.objects.size() : 0, BodyMotion{});
        wall_impulse_.assign(has_rigid_ ? ibp_count_ : 0, Vec3{0, 0, 0});
        contact_.init(setup.params, ibp_count_, setup.solids.size(),
                      std::size_t(std::count_if(setup.solids.begin(), setup.solids.end(),
                                                [](const SolidSetup& o) { return o.kind != SolidKind::kStatic; })),
                      has_rigid_);
        gp_rest_.upload(L.gp_rest);
        gp_offsets_.upload(L.gp_offsets);
        gp_links_.upload(L.gp_links);
        gp_weights_.upload(L.gp_weights);
        sbp_.upload(L.sbp);
        sbp_normal_.upload(L.sbp_normal);
        sbp_sides_.upload(L.sbp_sides);
        upload_surface_insets(L, setup);
        members_total_ = L.region_offsets.empty() ? 0 : L.region_offsets.back();
        object_count_ = setup.solids.size();
        // Each SBP's object, as an index into setup.solids (the layout's order: moving objects in
        // turn, each one's SBPs together), from the layout rather than from the number its
        // particles carry (setup.object), which is only a label.
        sbp_object_.clear();
        for (std::size_t o = 0; o < setup.solids.size(); ++o)
            if (setup.solids[o].kind != SolidKind::kStatic)
                sbp_object_.insert(sbp_object_.end(), setup.solids[o].sbp.size(), std::int32_t(o));
        if (sbp_object_.size() != sbp_count_) throw InputError("simulation setup: the SBPs' count differs from the layout's");
        // Each IBP's and SBP's object by slot (LSM reads the IBPs'; the lookahead, pcisph.hpp
        // SolidLookahead, both), and each object's IBP slots (contiguous, objects in order;
        // static objects: none) for its mean velocity.
        std::vector<std::int32_t> slot_object(L.ibp_object.begin(), L.ibp_object.end());
        slot_object.insert(slot_object.end(), sbp_object_.begin(), sbp_object_.end());
        object_.upload(slot_object);
        std::vector<std::uint32_t> ibp_begin(object_count_ + 1, 0);
        for (std::size_t s = 0; s < ibp_count_; ++s) ++ibp_begin[std::size_t(L.ibp_object[s]) + 1];
        for (std::size_t o = 0; o < object_count_; ++o) ibp_begin[o + 1] += ibp_begin[o];
        object_ibp_begin_.upload(ibp_begin);
        object_velocity_.assign(object_count_, Vec3{0, 0, 0});
        object_centroid_.assign(object_count_, Vec3{0, 0, 0});
        centroid_host_.assign(object_count_, Vec3{0, 0, 0});
        moving_names_.clear();
        for (std::size_t o = 0; o < object_count_; ++o)
            moving_names_.push_back(setup.solids[o].kind != SolidKind::kStatic ? setup.solids[o].name : "");
        upload_tension(setup, L.ibp_object);
        // Two-way coupling, only where there is fluid to push the solids (coupling.hpp); its
        // forces act through the regions (lsm.hpp, LsmData::forces).
        // A melting object makes fluid of its own (melting.hpp), and an emitter brings some
        // (emitter.hpp).
        const bool any_fluid =
            std::find(setup.type.begin(), setup.type.end(), std::uint8_t(kFluid)) != setup.type.end() ||
            std::any_of(setup.solids.begin(), setup.solids.end(), [](const SolidSetup& o) { return o.melts(); }) ||
            !setup.emitters.empty();
        if (setup.params.coupling.two_way && any_fluid) {
            const SurfaceShares shares = surface_shares(L);
            share_offsets_.upload(shares.offsets);
            share_sbp_.upload(shares.sbp);
            share_weight_.upload(shares.weight);
            reaction_.assign(ibp_count_ + sbp_count_, Vec3{0, 0, 0});
            force_.assign(ibp_count_, Vec3{0, 0, 0});
            region_acceleration_.assign(regions, Vec3{0, 0, 0});
            region_angular_acceleration_.assign(regions, Vec3{0, 0, 0});
            // The velocity–position correction's side of it (solid_contact.hpp): the SBPs' contact
            // masses, and the impulses they take, which wait for the next step's coupling.
            if (setup.params.coupling.correction) {
                sbp_inverse_mass_.upload(sbp_inverse_contact_mass(L, shares));
                sbp_impulse_.assign(sbp_count_, Vec3{0, 0, 0});
            }
        }
        // Melting objects (melting.hpp) rebuild their regions as they lose particles: the host
        // layout stays for that, and each one's lattice and first slot.
        for (std::size_t o = 0; o < setup.solids.size(); ++o) {
            const SolidSetup& solid = setup.solids[o];
            if (solid.kind != SolidKind::kElastic || !solid.melts()) continue;
            melting_.push_back(MeltingLattice{o, ibp_begin[o], solid.lattice, solid.region_half_width});
        }
        if (!melting_.empty()) host_layout_ = std::move(L);
        // The correction against the melting lattices' exposed vertices (melting_faces.hpp):
        // their normals, and two-way their contact masses and impulses, by IBP slot.
        // Interface tension on a melting object pulls toward the same faces, so it needs the
        // normals too.
        lattice_faces_met_ = !melting_.empty() && setup.params.coupling.correction;
        lattice_normal_.assign(lattice_faces_met_ || !lattice_eta_.empty() ? ibp_count_ : 0, Vec3{0, 0, 0});
        const bool lattice_takes_impulses = lattice_faces_met_ && !reaction_.empty();
        lattice_inverse_mass_.assign(lattice_takes_impulses ? ibp_count_ : 0, Real(0));
        lattice_impulse_.assign(lattice_takes_impulses ? ibp_count_ : 0, Vec3{0, 0, 0});
    }

    // Interface tension (interface_tension.hpp): each SBP's η, its object's, and each melting
    // object's lattice vertex's (IBP slots: its surface is its exposed vertices); none stored
    // where no object has any.
    void upload_tension(const SimulationSetup& setup, const std::vector<std::int32_t>& ibp_object) {
        auto upload = [&](DeviceArray<Real>& out, std::size_t count, auto eta_of) {
            std::vector<Real> eta(count, Real(0));
            bool any = false;
            for (std::size_t k = 0; k < count; ++k) any = (eta[k] = eta_of(k)) > Real(0) || any;
            if (any) out.upload(eta);
        };
        upload(sbp_eta_, sbp_count_, [&](std::size_t k) { return setup.solids[std::size_t(sbp_object_[k])].interface_tension; });
        upload(lattice_eta_, ibp_count_, [&](std::size_t k) {
            const SolidSetup& solid = setup.solids[std::size_t(ibp_object[k])];
            return solid.melts() ? solid.interface_tension : Real(0);
        });
    }

    // A melting object's lattice: its index in the setup's solids, its first IBP slot, its
    // lattice coordinates (slot order) and region half-width.
    struct MeltingLattice {
        std::size_t object = 0, base = 0;
        std::vector<std::array<int, 3>> lattice;
        int region_half_width = 2;
    };
    const std::vector<MeltingLattice>& melting_lattices() const { return melting_; }

    // Rebuilds the melting objects' regions over the IBP slots still `alive` (per IBP slot)
    // everywhere on the host, and uploads them (lsm_regions.hpp, rebuild_elastic_object_regions):
    // on loading a checkpoint. A step's melting rebuilds them on the device (melting_regions.hpp).
    void rebuild_melting_regions(const std::vector<std::uint8_t>& alive) {
        LsmHostLayout& L = host_layout_;
        for (const MeltingLattice& m : melting_)
            rebuild_elastic_object_regions(L, m.lattice, m.region_half_width, m.base, alive);
        member_index_.upload(L.member_index);
        region_end_.upload(L.region_end);
        regions_end_.upload(L.ibp_regions_end);
        split_mass_.upload(L.ibp_split_mass);
        region_mass_.upload(L.region_mass);
        region_c0_.upload(L.region_c0);
        region_A0_.upload(L.region_A0);
        region_inertia_inv_.upload(L.region_inertia_inv);
    }
    // The region arrays that melting rebuilds on the device (melting_regions.hpp).
    MeltingRegionArrays melting_region_arrays() {
        MeltingRegionArrays r;
        r.rest = rest_.cview().data();
        r.mass = mass_.cview().data();
        r.region_offsets = region_offsets_.cview().data();
        r.regions_begin = regions_begin_.cview().data();
        r.region_end = region_end_.view().data();
        r.regions_end = regions_end_.view().data();
        r.member_index = member_index_.view().data();
        r.split_mass = split_mass_.view().data();
        r.region_mass = region_mass_.view().data();
        r.region_c0 = region_c0_.view().data();
        r.region_A0 = region_A0_.view().data();
        r.region_inertia_inv = region_inertia_inv_.view().data();
        return r;
    }
    // The slot map (melting.hpp marks melted slots in it) and each IBP and SBP slot's object.
    View<std::uint32_t> slot_map() { return store_of_slot_.view(); }
    void slot_map_fill(std::uint32_t value) { store_of_slot_.fill(value); }
    View<const std::int32_t> slot_objects() const { return object_.cview(); }
    View<const std::uint8_t> pinned_slots() const { return pinned_.cview(); }  // per IBP slot
    DeviceArray<std::int32_t>& solid_slot_field() { return *solid_slot_; }
    View<const std::int32_t> solid_slot_view() const { return solid_slot_ ? solid_slot_->cview() : View<const std::int32_t>{}; }
    // The slots of the particles that meet the fluid: the IBPs, then the SBPs.
    std::size_t boundary_slot_count() const { return ibp_count_ + sbp_count_; }

    bool active() const { return ibp_count_ > 0; }
    bool has_rigid() const { return has_rigid_; }
    // Any object that answers inside PCISPH as one body (LsmObjectParams::body_answer).
    bool has_body_answer() const { return has_body_answer_; }
    Vec3 domain_min() const { return domain_min_; }
    Vec3 domain_max() const { return domain_max_; }
    // Whether the fluid's forces reach the solids (coupling.hpp): two-way coupling on, and fluid.
    bool coupled() const { return !force_.empty(); }
    std::size_t ibp_count() const { return ibp_count_; }
    std::size_t region_member_count() const { return members_total_; }
    std::size_t region_chunk_count() const { return chunk_begin_.size(); }

    // After the neighbour sort: slot -> store index.
    void update_slot_map(const ParticleStore& store) {
        build_slot_map(device_, store.moving_count(), solid_slot_->cview(), store_of_slot_.view());
    }

    // The module's stages, over `store` (init's): where PCISPH meets the solids (`predicted`:
    // where the step will take them, coupling.predict_solids; otherwise where they start it), and
    // one LSM step under `gravity` inside the domain box, in substeps no longer than `substep`.
    // The slot map must be current (the simulation rebuilds it after every sort).
    void plan(ParticleStore& store, Vec3 gravity, Vec3 domain_min, Vec3 domain_max, bool predicted, Real substep) {
        store_ = &store;
        substep_ = substep;
        gravity_ = gravity;
        domain_min_ = domain_min;
        domain_max_ = domain_max;
        predicts_ = predicted && active();
    }
    void bind(StepPlan& plan) override {
        if (!active()) return;
        if (predicts_)
            plan.bind("solid_volumes", [this](StepContext& step) { step.lookahead = lookahead(*store_, step.ranges); });
        plan.bind("lsm", [this](StepContext& step) {
            step.solid_motion = this->step(*store_, step.dt, gravity_, domain_min_, domain_max_, step.neighbors.grid);
        });
    }
    // The summary's reduction makes its workspace on first use: once here, before the first step.
    void start(const StepContext&) override {
        if (active()) summary(*store_);
    }

    // LSM substeps in a step of dt: one without an elastic object (a rigid fit does not sag) or
    // without solver.solid_substep, else the fewest no longer than it.
    int substeps(Real dt) const {
        if (!has_elastic_ || !(substep_ > Real(0)) || dt <= substep_) return 1;
        return int(std::ceil(double(dt) / double(substep_) * (1 - 1e-6)));
    }

    // One LSM step (the slot map must be current): regions and IBP update in substeps
    // (substeps()), whole-body damping, then GPs and SBPs once.
    SolidSummary step(ParticleStore& store, Real dt, Vec3 gravity, Vec3 domain_min, Vec3 domain_max,
                      const GridView& grid = GridView{}) {
        const LsmData d = data(store);
        LsmStepParams p;
        const int n = substeps(dt);
        p.dt = dt / Real(n);
        p.gravity = gravity;
        p.domain_min = domain_min;
        p.domain_max = domain_max;
        p.obstacles = contact_.obstacles();
        // The fluid's forces (a_ext) hold over the whole step: substeps apply the same impulse.
        // Each substep's contacts: the walls and static obstacles, then one solid with another.
        for (int k = 0; k < n; ++k) {
            lsm_region_update(device_, d);
            lsm_particle_update(device_, d, p);
            if (has_rigid_)
                lsm_rigid_walls(device_, d, p, object_ibp_begin_.view().data(), object_count_, wall_impulse_.view().data(),
                                contact_.obstacle_impulse());
            if (contact_.between_solids())
                solid_collisions(device_, contact_.collisions(d, grid, *solid_slot_, object_ibp_begin_.view().data()), p.dt);
        }
        if (body_motion_.size())
            lsm_body_damping(device_, d, dt, object_ibp_begin_.view().data(), object_count_, body_motion_.view().data());
        const InterpolationData g = interpolation(store);
        interpolate_geometry(device_, g, dt);
        interpolate_surface(device_, g);
        return summary(store);
    }

    // stats.csv: each moving object's centre of mass (of its IBPs that have not melted), m, as
    // NAME_x, NAME_y, NAME_z: how a body sinks, floats or drifts, step by step.
    void report_columns(std::vector<std::string>& names) const override {
        for (const std::string& name : moving_names_)
            if (!name.empty())
                for (const char* axis : {"_x", "_y", "_z"}) names.push_back("centroid_" + name + axis);
    }
    void report(std::vector<double>& values) const override {
        // Static objects only: no column, nothing to compute or copy.
        if (!store_ || std::all_of(moving_names_.begin(), moving_names_.end(),
                                   [](const std::string& name) { return name.empty(); }))
            return;
        // One small copy to the host, with the report's other sums.
        object_mass_means(store_->position.cview().data(), object_centroid_.view().data(), "solid_object_centroid");
        object_centroid_.download(centroid_host_);
        for (std::size_t o = 0; o < object_count_; ++o)
            if (!moving_names_[o].empty())
                values.insert(values.end(), {double(centroid_host_[o].x), double(centroid_host_[o].y),
                                             double(centroid_host_[o].z)});
    }

    // Per object, the mass-weighted mean of `field` (by store index) over its IBPs that have not
    // melted (0 for none): one thread per object sums its IBP slots in order, deterministic.
    // Public: CUDA allows no device lambda in a private member function.
    void object_mass_means(const Vec3* field, Vec3* mean, const char* kernel_name) const {
        const std::uint32_t* store_of_slot = store_of_slot_.view().data();
        const std::uint32_t* begin = object_ibp_begin_.view().data();
        const Real* mass = mass_.view().data();
        parallel_for(device_, kernel_name, object_count_, [=] MW_HD(std::size_t o) {
            Vec3 sum{0, 0, 0};
            Real total = 0;
            for (std::uint32_t s = begin[o]; s < begin[o + 1]; ++s) {
                if (store_of_slot[s] == kMeltedSlot) continue;
                sum += mass[s] * field[store_of_slot[s]];
                total += mass[s];
            }
            mean[o] = total > Real(0) ? sum / total : Vec3{0, 0, 0};
        });
    }

    // Where PCISPH meets the moving solids this step (pcisph.hpp, SolidLookahead): each soft
    // object's mean velocity (its momentum over its mass), and the way from a store index to its
    // object. The slot map must
    // be current.
    SolidLookahead lookahead(const ParticleStore& store, const GroupRanges& ranges) {
        const Vec3* velocity = store.velocity.cview().data();
        Vec3* mean = object_velocity_.view().data();
        object_mass_means(velocity, mean, "solid_object_velocity");
        SolidLookahead l;
        l.velocity = velocity;
        l.object_velocity = mean;
        l.objects = objects_.view().data();
        l.solid_slot = solid_slot_->cview().data();
        l.slot_object = object_.view().data();
        l.begin = ranges.fluid_end;
        l.end = ranges.solid_end;
        return l;
    }

    // The IBPs' kinetic energy, top speed and first non-finite slot (a reduction read back).
    SolidSummary summary(ParticleStore& store) { return summarize_solids(device_, data(store)); }

    // The current goal of every IBP (slot order), without changing anything but the warm-start
    // rotations (tests).
    std::vector<Vec3> goals(ParticleStore& store) {
        update_slot_map(store);
        const LsmData d = data(store);
        lsm_region_update(device_, d);
        DeviceArray<Vec3> goal(ibp_count_);
        lsm_goals(device_, d, goal.view());
        return goal.to_host();
    }

    // Scene index of the IBP in a slot is not kept on the device; this gives the store index.
    std::uint32_t store_index_of_slot(std::size_t slot) const {
        std::uint32_t i = 0;
        store_of_slot_.download_range(&i, slot, 1);
        return i;
    }

    // Each object's IBP slots and their masses (the strong coupling's per-object sums).
    // What the cloths' answer inside PCISPH reads (coupling.hpp, NodeResponse), less its own arrays.
    NodeResponse node_response() const {
        NodeResponse n;
        n.object_begin = object_ibp_begin_.view().data();
        n.params = objects_.view().data();
        n.slot_object = object_.view().data();
        n.store_of_slot = store_of_slot_.view().data();
        n.pinned = pinned_.view().data();
        n.force = force_.view().data();
        n.regions_begin = regions_begin_.view().data();
        n.regions_end = regions_end_.view().data();
        n.region_offsets = region_offsets_.view().data();
        n.region_end = region_end_.view().data();
        n.member_index = member_index_.view().data();
        n.region_mass = region_mass_.view().data();
        n.sbp = sbp_.view().data();
        n.gp_offsets = gp_offsets_.view().data();
        n.gp_links = gp_links_.view().data();
        n.gp_weights = gp_weights_.view().data();
        n.ibp_count = static_cast<std::uint32_t>(ibp_count_);
        n.sbp_count = static_cast<std::uint32_t>(sbp_count_);
        n.object_count = object_count_;
        return n;
    }
    bool has_cloth() const { return has_cloth_; }

    ObjectIbps object_ibps() const {
        ObjectIbps o;
        o.begin = object_ibp_begin_.view().data();
        o.store_of_slot = store_of_slot_.view().data();
        o.mass = mass_.view().data();
        o.params = objects_.view().data();
        o.count = object_count_;
        return o;
    }

    // The coupling's arrays (coupled() only); the slot map must be current.
    CouplingData coupling() {
        CouplingData c;
        c.store_of_slot = store_of_slot_.view().data();
        c.ibp_count = static_cast<std::uint32_t>(ibp_count_);
        c.sbp_count = static_cast<std::uint32_t>(sbp_count_);
        c.reaction = reaction_.view().data();
        c.force = force_.view().data();
        c.share_offsets = share_offsets_.view().data();
        c.share_sbp = share_sbp_.view().data();
        c.share_weight = share_weight_.view().data();
        if (!sbp_impulse_.empty()) c.sbp_contact_impulse = sbp_impulse_.view().data();
        if (!lattice_impulse_.empty()) c.lattice_contact_impulse = lattice_impulse_.view().data();
        if (!sbp_eta_.empty()) c.sbp_eta = sbp_eta_.view().data();
        if (!lattice_eta_.empty()) {
            c.lattice_eta = lattice_eta_.view().data();
            c.type = store_->type.cview().data();
            c.lattice_normal = lattice_normal_.view().data();
        }
        c.faces = sbp_faces();
        return c;
    }

    // The solids' surface for the velocity–position correction (virtual_boundary.hpp), over this
    // step's grid.
    SolidSurface surface(const ParticleStore& store, const GridView& grid, Real band, Real reach) const {
        SolidSurface c;
        c.grid = grid;
        c.type = store.type.cview();
        c.solid_slot = solid_slot_->cview();
        if (sbp_count_ > 0) c.sbp_normal = sbp_normal_.view().data();
        c.sbp_inset = sbp_faces().inset;
        if (!sbp_sides_.empty()) c.sbp_sides = sbp_sides_.view().data();
        if (!sbp_inverse_mass_.empty()) c.sbp_inverse_mass = sbp_inverse_mass_.view().data();
        if (lattice_faces_met_) c.lattice_normal = lattice_normal_.view().data();
        if (!lattice_inverse_mass_.empty()) c.lattice_inverse_mass = lattice_inverse_mass_.view().data();
        c.lattice_inset = lattice_face_offset(reach);
        c.ibp_count = static_cast<std::uint32_t>(ibp_count_);
        c.sbp_count = static_cast<std::uint32_t>(sbp_count_);
        c.band = band;
        c.reach = reach;
        c.sbp_reach = Real(1.001) * (reach + largest_inset_);  // a margin over rounding: the SBPs' gather has no such test
        return c;
    }
    // The correction after the integration (solid_contact.hpp); the slot map must be current.
    // With two-way coupling the SBPs have finite contact masses and take impulses
    // (`impulse_per_weight`: per fluid particle, the caller's); one-way, none.
    SolidContactData contact(const SolidSurface& surface, Real slip, Real fluid_mass, Vec3* impulse_per_weight) {
        SolidContactData c;
        c.surface = surface;
        c.store_of_slot = store_of_slot_.view().data();
        if (!sbp_impulse_.empty()) c.sbp_impulse = sbp_impulse_.view().data();
        if (!lattice_impulse_.empty()) c.lattice_impulse = lattice_impulse_.view().data();
        if (contact_takes_impulses()) c.impulse_per_weight = impulse_per_weight;
        c.slip = slip;
        c.fluid_inverse_mass = Real(1) / fluid_mass;
        return c;
    }
    // Whether the correction exchanges momentum with the solids (two-way coupling and the
    // correction on).
    bool contact_takes_impulses() const { return !sbp_impulse_.empty() || !lattice_impulse_.empty(); }
    // The melting lattices' exposed vertices as the correction meets them, by IBP slot, for the
    // melting module to fill each step (melting_faces.hpp); null normals: not met.
    LatticeFaceArrays lattice_faces() {
        LatticeFaceArrays f;
        if (!lattice_normal_.empty()) f.normal = lattice_normal_.view().data();
        if (!lattice_inverse_mass_.empty()) f.inverse_mass = lattice_inverse_mass_.view().data();
        if (!lattice_impulse_.empty()) f.impulse = lattice_impulse_.view().data();
        return f;
    }
    // Interface tension (interface_tension.hpp): whether any object has it, and its eta per SBP.
    bool has_tension() const { return !sbp_eta_.empty() || !lattice_eta_.empty(); }
    const Real* sbp_eta() const { return sbp_eta_.empty() ? nullptr : sbp_eta_.view().data(); }
    // The same per IBP slot for the melting objects' lattices (null: none with tension).
    const Real* lattice_eta() const { return lattice_eta_.empty() ? nullptr : lattice_eta_.view().data(); }


    // The force on each object's IBPs in the last step (N, summed in double on the host),
    // indexed like SimulationSetup::solids; static objects and uncoupled runs give 0. A copy to
    // the host: for tests and reports, not for the step.
    std::vector<std::array<double, 3>> object_forces() const {
        if (!coupled()) return sum_by_object({}, {});
        return sum_by_object(force_.to_host(), object_.to_host());  // force_: the IBP slots only
    }
    // The impulse each object's SBPs took in the last step's velocity–position correction, which
    // the next step's coupling applies (kg m/s, summed in double on the host; 0 without it). For
    // tests: momentum is kept only counting it.
    std::vector<std::array<double, 3>> object_contact_impulses() const {
        std::vector<std::array<double, 3>> total = sum_by_object(sbp_impulse_.to_host(), sbp_object_);
        if (!lattice_impulse_.empty()) {
            const std::vector<std::int32_t> slot_object = object_.to_host();  // IBP slots first
            const std::vector<std::array<double, 3>> lattice = sum_by_object(lattice_impulse_.to_host(), slot_object);
            for (std::size_t o = 0; o < total.size(); ++o)
                for (int a = 0; a < 3; ++a) total[o][a] += lattice[o][a];
        }
        return total;
    }
    View<const Vec3> sbp_normals() const { return sbp_normal_.cview(); }
    // Where the SBPs meet the fluid (solid_face.hpp), and whether any sits inside its face.
    SbpFaces sbp_faces() const {
        return SbpFaces{sbp_normal_.view().data(), sbp_inset_.empty() ? nullptr : sbp_inset_.view().data()};
    }
    bool surface_inset() const { return !sbp_inset_.empty(); }
    // Whether the correction meets melting lattices, whose faces lie in front of their vertices.
    bool lattice_faces_met() const { return lattice_faces_met_; }
    // The melting lattices' exposed vertices' normals, by IBP slot (null: not computed), for
    // interface tension's face points.
    const Vec3* lattice_normals() const { return lattice_normal_.empty() ? nullptr : lattice_normal_.view().data(); }

    // Checkpoints (state_archive.hpp): what the solids carry from one step to the next. The
    // layout (rest shape, regions, links) is rebuilt from the scene; this is the rest: the
    // regions' rotations (the warm start of the next polar decomposition), the surface normals
    // (read by the next step's correction before LSM rewrites them), the impulses the correction
    // left for the next step's coupling, and the per-step arrays that are cheap to keep (so that
    // no read-before-write of one can make a resumed run differ). A solid particle's slot travels
    // with the store's fields.
    void save(StateArchive& archive) const override {
        for_each_state_array(*this, [&](const char* name, const auto& array) { archive.put(name, array.to_host()); });
    }
    void load(const StateArchive& archive) override {
        for_each_state_array(*this, [&](const char* name, auto& array) {
            using T = typename std::decay_t<decltype(array.to_host())>::value_type;
            array.upload(archive.get_sized<T>(name, array.size()));
        });
    }

    std::size_t bytes() const override {
        return store_of_slot_.bytes() + rest_.bytes() + mass_.bytes() + split_mass_.bytes() + object_.bytes() +
               pinned_.bytes() + regions_begin_.bytes() + regions_end_.bytes() + force_.bytes() + displacement_.bytes() +
               mean_rotation_.bytes() + region_offsets_.bytes() + region_end_.bytes() + member_index_.bytes() + region_mass_.bytes() +
               region_c0_.bytes() + region_A0_.bytes() + region_inertia_inv_.bytes() + region_object_.bytes() +
               region_chunks_.bytes() + chunk_begin_.bytes() + chunk_region_.bytes() +
               chunk_sums_.bytes() +
               rotation_.bytes() + rotation_matrix_.bytes() + mean_displacement_.bytes() + region_velocity_.bytes() + region_omega_.bytes() +
               region_acceleration_.bytes() + region_angular_acceleration_.bytes() +
               objects_.bytes() + gp_rest_.bytes() + gp_offsets_.bytes() + gp_links_.bytes() + gp_weights_.bytes() +
               sbp_.bytes() + sbp_normal_.bytes() + sbp_sides_.bytes() + sbp_inset_.bytes() + reaction_.bytes() + share_offsets_.bytes() + share_sbp_.bytes() +
               share_weight_.bytes() + sbp_inverse_mass_.bytes() + sbp_impulse_.bytes() + lattice_normal_.bytes() +
               lattice_inverse_mass_.bytes() + lattice_impulse_.bytes() + sbp_eta_.bytes() + lattice_eta_.bytes() +
               object_ibp_begin_.bytes() + object_velocity_.bytes() + wall_impulse_.bytes() +
               body_motion_.bytes() + contact_.bytes();
    }

    LsmData data(ParticleStore& store) {
        LsmData d;
        d.position = store.position.view().data();
        d.velocity = store.velocity.view().data();
        d.store_of_slot = store_of_slot_.view().data();
        d.ibp_count = static_cast<std::uint32_t>(ibp_count_);
        d.rest = rest_.view().data();
        d.mass = mass_.view().data();
        d.split_mass = split_mass_.view().data();
        d.object = object_.view().data();
        d.pinned = pinned_.view().data();
        d.regions_begin = regions_begin_.view().data();
        d.regions_end = regions_end_.view().data();
        d.forces = coupled();
        d.force = force_.view().data();
        d.displacement = displacement_.view().data();
        d.mean_rotation = mean_rotation_.view().data();
        d.region_count = static_cast<std::uint32_t>(region_mass_.size());
        d.region_offsets = region_offsets_.view().data();
        d.region_end = region_end_.view().data();
        d.member_index = member_index_.view().data();
        d.region_mass = region_mass_.view().data();
        d.region_c0 = region_c0_.view().data();
        d.region_A0 = region_A0_.view().data();
        d.region_inertia_inv = region_inertia_inv_.view().data();
        d.region_object = region_object_.view().data();
        d.chunk_count = static_cast<std::uint32_t>(chunk_begin_.size());
        d.region_chunks = region_chunks_.view().data();
        d.chunk_begin = chunk_begin_.view().data();
        d.chunk_region = chunk_region_.view().data();
        d.chunk_sums = chunk_sums_.view().data();
        d.rotation = rotation_.view().data();
        d.rotation_matrix = rotation_matrix_.view().data();
        d.mean_displacement = mean_displacement_.view().data();
        d.region_velocity = region_velocity_.view().data();
        d.region_omega = region_omega_.view().data();
        d.region_acceleration = region_acceleration_.view().data();
        d.region_angular_acceleration = region_angular_acceleration_.view().data();
        d.objects = objects_.view().data();
        return d;
    }

    InterpolationData interpolation(ParticleStore& store) {
        InterpolationData g;
        g.position = store.position.view().data();
        g.velocity = store.velocity.view().data();
        g.store_of_slot = store_of_slot_.view().data();
        g.ibp_rest = rest_.view().data();
        g.mean_rotation = mean_rotation_.view().data();
        g.sbp_first = static_cast<std::uint32_t>(ibp_count_);
        g.gp_first = static_cast<std::uint32_t>(ibp_count_ + sbp_count_);
        g.gp_count = static_cast<std::uint32_t>(gp_count_);
        g.sbp_count = static_cast<std::uint32_t>(sbp_count_);
        g.gp_rest = gp_rest_.view().data();
        g.gp_offsets = gp_offsets_.view().data();
        g.gp_links = gp_links_.view().data();
        g.gp_weights = gp_weights_.view().data();
        g.sbp = sbp_.view().data();
        g.sbp_normal = sbp_normal_.view().data();
        if (!sbp_inset_.empty()) {
            g.sbp_inset = sbp_inset_.view().data();
            g.wall_lo = fade_lo_;
            g.wall_hi = fade_hi_;
            g.inset_fade = inset_fade_;
            g.boxes = contact_.obstacles().boxes;
        }
        return g;
    }

   private:
    // The SBPs' insets (solid_face.hpp), kept only where one is set in (null faces otherwise: no
    // read in the gathers): each one's where the scene starts, faded near the walls as the scene
    // builder placed it and each step will.
    void upload_surface_insets(const LsmHostLayout& L, const SimulationSetup& setup) {
        Real largest = 0;
        for (const SbpLink& link : L.sbp) largest = std::max(largest, link.inset);
        if (!(largest > Real(0))) {
            sbp_inset_.resize(0);
            largest_inset_ = 0;
            return;
        }
        const BoundaryParams& b = setup.params.boundary;
        inset_fade_ = surface_inset_fade(b.walls, setup.params.fluid.support_radius, b.wall_gap, b.static_boxes);
        faces_to_fade_at(b.walls, setup.params.domain_min, setup.params.domain_max, fade_lo_, fade_hi_);
        std::vector<Real> start(L.sbp_count);
        for (std::size_t k = 0; k < L.sbp_count; ++k) {
            const SbpLink& link = L.sbp[k];
            const Vec3 face = link.bary.x * L.gp_rest[link.corner[0]] + link.bary.y * L.gp_rest[link.corner[1]] +
                              link.bary.z * L.gp_rest[link.corner[2]];
            start[k] = faded_inset(link.inset, face, L.sbp_normal[k], fade_lo_, fade_hi_, inset_fade_, b.static_boxes);
        }
        sbp_inset_.upload(start);
        largest_inset_ = largest;
    }

    // Visits each state array of `self` (a SolidBodies, const or not) with its block name.
    template <class Self, class Visit>
    static void for_each_state_array(Self& self, Visit&& visit) {
        visit("solids.rotation", self.rotation_);
        visit("solids.rotation_matrix", self.rotation_matrix_);
        visit("solids.mean_rotation", self.mean_rotation_);
        visit("solids.displacement", self.displacement_);
        visit("solids.mean_displacement", self.mean_displacement_);
        visit("solids.region_velocity", self.region_velocity_);
        visit("solids.region_omega", self.region_omega_);
        visit("solids.region_acceleration", self.region_acceleration_);
        visit("solids.region_angular_acceleration", self.region_angular_acceleration_);
        visit("solids.force", self.force_);
        visit("solids.reaction", self.reaction_);
        visit("solids.sbp_normal", self.sbp_normal_);
        visit("solids.sbp_inset", self.sbp_inset_);
        visit("solids.sbp_impulse", self.sbp_impulse_);
        visit("solids.lattice_impulse", self.lattice_impulse_);
    }

    // Per-particle vectors summed in double per object (indexed like SimulationSetup::solids).
    std::vector<std::array<double, 3>> sum_by_object(const std::vector<Vec3>& values,
                                                     const std::vector<std::int32_t>& object) const {
        std::vector<std::array<double, 3>> total(object_count_, std::array<double, 3>{0, 0, 0});
        for (std::size_t k = 0; k < values.size(); ++k) {
            std::array<double, 3>& t = total[std::size_t(object[k])];
            t[0] += values[k].x;
            t[1] += values[k].y;
            t[2] += values[k].z;
        }
        return total;
    }

    const DeviceContext& device_;
    ParticleStore* store_ = nullptr;  // plan()'s
    Vec3 gravity_{0, 0, 0}, domain_min_{0, 0, 0}, domain_max_{0, 0, 0};
    bool predicts_ = false;
    std::size_t ibp_count_ = 0, sbp_count_ = 0, gp_count_ = 0, members_total_ = 0, object_count_ = 0;
    bool has_rigid_ = false;  // any rigid object (lsm_rigid_walls)
    bool has_cloth_ = false;  // any cloth (its nodes answer inside PCISPH)
    bool has_elastic_ = false;  // any elastic object (substeps())
    bool has_body_answer_ = false;  // any object answering inside PCISPH as one body
    Real substep_ = 0;          // solver.solid_substep
    DeviceArray<Vec3> wall_impulse_;  // per IBP of a rigid object, its walls' impulses this step
    DeviceArray<BodyMotion> body_motion_;  // per object, with lsm.body_damping: its rigid motion this step
    SolidContactState contact_;  // the static obstacles and the contacts between solids
    DeviceArray<std::int32_t>* solid_slot_ = nullptr;  // owned by the store
    DeviceArray<std::uint32_t> store_of_slot_;
    DeviceArray<Vec3> rest_;
    DeviceArray<Real> mass_, split_mass_;
    DeviceArray<std::int32_t> object_;  // per IBP and SBP slot, its object (index into setup.solids)
    DeviceArray<std::uint8_t> pinned_;
    DeviceArray<std::uint32_t> regions_begin_, regions_end_;
    DeviceArray<Vec3> force_;  // per IBP, the coupling's (empty without it)
    DeviceArray<Vec3> displacement_;  // u = x - x0 per IBP, rewritten every LSM step
    DeviceArray<Mat3> mean_rotation_;
    DeviceArray<std::uint32_t> region_offsets_, region_end_, member_index_;
    DeviceArray<Real> region_mass_;
    DeviceArray<Vec3> region_c0_;
    DeviceArray<SymMat3> region_A0_, region_inertia_inv_;
    DeviceArray<std::int32_t> region_object_;
    DeviceArray<std::uint32_t> region_chunks_, chunk_begin_, chunk_region_;
    DeviceArray<RegionSums> chunk_sums_;
    DeviceArray<Quat> rotation_;
    DeviceArray<Mat3> rotation_matrix_;
    DeviceArray<Vec3> mean_displacement_, region_velocity_, region_omega_;
    DeviceArray<Vec3> region_acceleration_, region_angular_acceleration_;  // under coupling only
    DeviceArray<LsmObjectParams> objects_;
    DeviceArray<Vec3> gp_rest_;
    DeviceArray<std::uint32_t> gp_offsets_, gp_links_;
    DeviceArray<Real> gp_weights_;
    DeviceArray<SbpLink> sbp_;
    DeviceArray<Vec3> sbp_normal_;
    DeviceArray<std::uint8_t> sbp_sides_;  // SbpSides; empty: every SBP one-sided (no cloth or rod)
    DeviceArray<Real> sbp_inset_;  // m, by SBP index, this step's (faded); empty: every SBP on its face
    Real inset_fade_ = 0;          // m (interpolate_surface)
    Vec3 fade_lo_{0, 0, 0}, fade_hi_{0, 0, 0};  // the domain's faces the fade sees (none without walls)
    Real largest_inset_ = 0;       // m
    // Two-way coupling (coupling.hpp): this step's reaction per IBP and SBP slot, and the SBPs'
    // shares of each IBP.
    DeviceArray<Vec3> reaction_;
    DeviceArray<std::uint32_t> share_offsets_, share_sbp_;
    DeviceArray<Real> share_weight_;
    // The velocity–position correction under two-way coupling (solid_contact.hpp): per SBP.
    DeviceArray<Real> sbp_inverse_mass_;
    DeviceArray<Vec3> sbp_impulse_;
    DeviceArray<Vec3> lattice_normal_;        // per IBP slot, with a melting object (melting_faces.hpp)
    bool lattice_faces_met_ = false;          // the correction meets the melting lattices' faces
    DeviceArray<Real> lattice_inverse_mass_;  // per IBP slot, the same, two-way
    DeviceArray<Vec3> lattice_impulse_;       // per IBP slot, the same, two-way
    DeviceArray<Real> sbp_eta_;  // interface tension η per SBP (empty: none)
    DeviceArray<Real> lattice_eta_;  // ... per IBP slot, a melting object's (empty: none)
    DeviceArray<std::uint32_t> object_ibp_begin_;  // per object, its first IBP slot (and one past the last)
    DeviceArray<Vec3> object_velocity_;            // per object, this step's mean velocity
    mutable DeviceArray<Vec3> object_centroid_;    // per object, its centre of mass (report())
    mutable std::vector<Vec3> centroid_host_;      // host: the same
    std::vector<std::string> moving_names_;        // per object, its name ("" for a static one)
    std::vector<std::int32_t> sbp_object_;  // host: each SBP's object
    std::vector<MeltingLattice> melting_;   // host: the melting objects' lattices
    LsmHostLayout host_layout_;             // host: the layout, kept only when an object melts
};

MW_BACKEND_END
