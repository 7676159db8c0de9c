// Fluid emitters: streams of fluid entering the scene through a disc (the paper's Figs. 1, 8-11
// pour a stream onto their solids). Each emitter releases a layer of particles, a square lattice
// at spacing r0 over its disc, every r0 / speed seconds, moving at `speed` along its direction, so
// that the layers leave r0 apart and the stream starts at the fluid's rest spacing in all three
// directions: a steady flux of rest density × speed × (the layer's particles × r0²).
//
// The particles exist from the start: the scene builder appends every layer an emitter will
// release as particles of type kPending, which the neighbour grid sorts with the inactive group
// (after the solids) and no sum reads. Emitting one is a change of type in place, as melting is
// (the store allows a particle to change type; its id, the index the scene gave it, tells which
// layer and which point of the disc it is): no allocation, no host copy, one launch on a step that
// emits and nothing on the others. The next step's sort moves the new fluid into the fluid range.
//
// Timing: layer k leaves the disc at t_k = start + k r0 / speed. The stage runs at the end of a
// step, and a layer due within it is placed where it would be at the step's end, t_k + τ: the
// disc's point plus speed τ along the direction and g τ²/2, with velocity speed + g τ. So a step
// longer than r0 / speed releases several layers, each at its own distance: the stream does not
// depend on the step. Nothing keeps fluid from flowing back over the disc: keep it clear of
// fluid (docs/scenes.md, "emitters").
//
// The nozzle: a layer stays on that path, whatever the pressure says, until it is the support
// radius h from its disc (where it still lies within r0/2 of it: a particle something has turned
// aside is let go). Released free, the newest layer is pushed back by the pressure of the layer
// in front and the next is released onto it, closer than r0: a horizontal jet at 4 m/s in open
// air reached 11 m/s within 0.1 s that way (EPYC VM; a falling stream hid it, as gravity draws its
// layers apart). Fluid beyond the nozzle meets a piston, as it does at a real one's mouth.
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/module.hpp"
#include "algorithms/particle_store.hpp"
#include "algorithms/particle_types.hpp"
#include "simulation/simulation.hpp"
#include "algorithms/state_archive.hpp"
#include "backend/backend.hpp"

MW_BACKEND_BEGIN

// One emitter: its layers' geometry and timing, kept for the run, and, in a step's windows, the
// ids of its particles to release in that step, [first_id, end_id).
struct EmitterWindow {
    std::uint32_t first_id = 0, end_id = 0;  // this step's (empty in the kept copy)
    std::uint32_t held_id = 0;               // [held_id, first_id): fluid still in the nozzle
    std::uint32_t base_id = 0;               // its first particle's id
    std::uint32_t per_layer = 0;
    std::uint32_t offsets_begin = 0;         // its layer's points in the shared offsets array
    Vec3 center{0, 0, 0}, direction{0, 0, 0};
    Real speed = 0;
    Real temperature = 0;
    double start = 0, interval = 0;  // t_k = start + k interval
};
struct EmitterWindows {
    EmitterWindow e[kMaxEmitters];
    std::uint32_t count = 0;
};

// What the release kernel writes (store fields; temperature null without heat conduction).
struct EmissionData {
    const std::uint32_t* id = nullptr;
    std::uint8_t* type = nullptr;
    Vec3* position = nullptr;
    Vec3* velocity = nullptr;
    std::int32_t* object = nullptr;
    Real* density = nullptr;
    Real* temperature = nullptr;
    const Vec3* offsets = nullptr;
    Real rest_density = 0;
    Vec3 gravity{0, 0, 0};
    double time_after = 0;  // the step's end, s
    Real hold_reach = 0;    // m: a particle in the nozzle this far from its path is let go
};

// Over the store's particles [begin, end): each pending particle whose id is in a window's
// release range becomes fluid at its layer's place, and each fluid particle in its nozzle range
// is put back on its path (the nozzle, above).
inline void release_layers(const DeviceContext& device, std::size_t begin, std::size_t end, const EmitterWindows windows, const EmissionData d) {
    parallel_for(device, "emitter_release", end - begin, [=] MW_HD(std::size_t k) {
        const std::size_t i = begin + k;
        const std::uint8_t type = d.type[i];
        if (type != kPending && type != kFluid) return;
        const std::uint32_t id = d.id[i];
        for (std::uint32_t w = 0; w < windows.count; ++w) {
            const EmitterWindow& e = windows.e[w];
            const bool release = type == kPending && id >= e.first_id && id < e.end_id;
            const bool hold = type == kFluid && id >= e.held_id && id < e.first_id;
            if (!release && !hold) continue;
            const std::uint32_t n = id - e.base_id, layer = n / e.per_layer, point = n % e.per_layer;
            const Real tau = static_cast<Real>(d.time_after - (e.start + double(layer) * e.interval));
            const Vec3 x = e.center + d.offsets[e.offsets_begin + point] + (e.speed * tau) * e.direction +
                           (Real(0.5) * tau * tau) * d.gravity;
            if (hold && !(norm2(d.position[i] - x) < d.hold_reach * d.hold_reach)) return;
            d.position[i] = x;
            d.velocity[i] = e.speed * e.direction + tau * d.gravity;
            if (hold) return;
            d.type[i] = kFluid;
            d.object[i] = -1;
            d.density[i] = d.rest_density;
            if (d.temperature) d.temperature[i] = e.temperature;
            return;
        }
    });
}

// The emitters module (stage "emit", with an emitter): the emitters' layers, and how many each
// has released.
class FluidEmitters final : public Module {
   public:
    // Checks the setup's emitters (their particles must be pending, layer by layer, as
    // EmitterSetup says) and uploads their layers' points. Throws InputError naming the emitter.
    // The heat's store field `temperature`, when there is one, takes the streams' temperatures.
    FluidEmitters(const DeviceContext& device, const SimulationSetup& setup, ParticleStore& store,
                  ParticleCounts& counts, Real rest_density, Vec3 gravity)
        : device_(device), store_(store), counts_(counts), rest_density_(rest_density), gravity_(gravity) {
        const Real spacing = setup.params.fluid.spacing;
        nozzle_length_ = setup.params.fluid.support_radius;
        hold_reach_ = Real(0.5) * spacing;
        if (setup.emitters.size() > kMaxEmitters)
            throw InputError("simulation setup: " + std::to_string(setup.emitters.size()) + " emitters, at most " +
                             std::to_string(kMaxEmitters) + " are supported");
        std::vector<Vec3> offsets;
        for (const EmitterSetup& s : setup.emitters) {
            const std::string name = "simulation setup: emitter \"" + s.name + "\": ";
            if (!(s.speed > 0) || !std::isfinite(double(s.speed))) throw InputError(name + "speed must be > 0");
            if (!(std::fabs(double(norm(s.direction)) - 1) < 1e-5)) throw InputError(name + "direction must be a unit vector");
            if (s.offsets.empty() || s.layers == 0) throw InputError(name + "releases no particle");
            const std::size_t count = std::size_t(s.layers) * s.offsets.size();
            if (std::size_t(s.first) + count > setup.type.size())
                throw InputError(name + "its particles reach past the setup's lists");
            for (std::size_t i = s.first; i < s.first + count; ++i)
                if (setup.type[i] != kPending) throw InputError(name + "particle " + std::to_string(i) + " is not pending");
            EmitterWindow w;
            w.base_id = w.first_id = w.end_id = s.first;
            w.per_layer = static_cast<std::uint32_t>(s.offsets.size());
            w.offsets_begin = static_cast<std::uint32_t>(offsets.size());
            w.center = s.center;
            w.direction = s.direction;
            w.speed = s.speed;
            w.temperature = s.temperature;
            w.start = s.start;
            w.interval = double(spacing) / double(s.speed);
            emitters_.push_back(w);
            layers_.push_back(s.layers);
            offsets.insert(offsets.end(), s.offsets.begin(), s.offsets.end());
        }
        released_.assign(emitters_.size(), 0);
        if (!offsets.empty()) offsets_.upload(offsets);
        temperature_ = store.find<Real>("temperature");
    }
    bool active() const { return !emitters_.empty(); }

    void bind(StepPlan& plan) override {
        if (active()) plan.bind("emit", [this](StepContext& step) { emit(step); });
    }
    // The layers due by the step's end leave their discs as fluid (the next step's sort moves them
    // to the fluid's range).
    void emit(StepContext& step) {
        step.released =
            this->step(store_, step.time + step.dt, gravity_, rest_density_, temperature_);
        counts_.by_type[kFluid] += step.released;
        counts_.by_type[kPending] -= step.released;
    }
    double speed_to_come(double time) const override { return fastest_after(time); }
    void report_columns(std::vector<std::string>& names) const override {
        if (active()) names.push_back("emitted");
    }
    void report(std::vector<double>& values) const override {
        if (active()) values.push_back(double(released_total_));
    }

    // Releases every layer due by `time_after` (the step's end) and holds the nozzle's layers on
    // their paths; returns how many particles it released.
    long step(ParticleStore& store, double time_after, Vec3 gravity, Real rest_density,
              DeviceArray<Real>* temperature) {
        EmitterWindows windows;
        long released = 0;
        for (std::size_t k = 0; k < emitters_.size(); ++k) {
            const std::uint32_t due = layers_due(k, time_after);
            // Layers that left after time_after - (nozzle length / speed) are still in the nozzle.
            const std::uint32_t out = layers_due(k, time_after - double(nozzle_length_) / double(emitters_[k].speed));
            const std::uint32_t held = std::min(out, released_[k]);
            if (due <= held) continue;
            EmitterWindow w = emitters_[k];
            w.held_id = w.base_id + held * w.per_layer;
            w.first_id = w.base_id + released_[k] * w.per_layer;
            w.end_id = w.base_id + due * w.per_layer;
            windows.e[windows.count++] = w;
            released += long(due - released_[k]) * long(w.per_layer);
            released_[k] = due;
        }
        if (windows.count == 0) return 0;
        EmissionData d;
        d.id = store.id.cview().data();
        d.type = store.type.view().data();
        d.position = store.position.view().data();
        d.velocity = store.velocity.view().data();
        d.object = store.object.view().data();
        d.density = store.density.view().data();
        d.temperature = temperature ? temperature->view().data() : nullptr;
        d.offsets = offsets_.cview().data();
        d.rest_density = rest_density;
        d.gravity = gravity;
        d.time_after = time_after;
        d.hold_reach = hold_reach_;
        // The nozzle's fluid is in the fluid range (sorted there after its release), the layers
        // to release in the inactive group: both, from the start.
        release_layers(device_, 0, store.moving_count(), windows, d);
        released_total_ += released;
        return released;
    }

    // Particles released since the scene started, and all it will release.
    long released_total() const { return released_total_; }
    long capacity() const {
        long total = 0;
        for (std::size_t k = 0; k < emitters_.size(); ++k) total += long(layers_[k]) * long(emitters_[k].per_layer);
        return total;
    }
    // The fastest emitter still to release a layer after `time`: the next CFL step must not carry
    // its new layers more than the CFL distance (0 when none is left).
    double fastest_after(double time) const {
        double fastest = 0;
        for (std::size_t k = 0; k < emitters_.size(); ++k)
            if (layers_due(k, time) < layers_[k]) fastest = std::max(fastest, double(emitters_[k].speed));
        return fastest;
    }

    void save(StateArchive& out) const override {
        if (active()) out.put("emitters.released_layers", released_);
    }
    // After the store is loaded: the layers released so far (its pending particles must match).
    void load(const StateArchive& in) override {
        if (emitters_.empty()) return;
        released_ = in.get_sized<std::uint32_t>("emitters.released_layers", emitters_.size());
        released_total_ = 0;
        for (std::size_t k = 0; k < emitters_.size(); ++k) {
            if (released_[k] > layers_[k]) throw InputError("checkpoint: an emitter released more layers than it has");
            released_total_ += long(released_[k]) * long(emitters_[k].per_layer);
        }
        if (counts_.by_type[kPending] != capacity() - released_total_)
            throw InputError("checkpoint: its pending particles do not match its emitters' released layers");
    }

    std::size_t bytes() const override { return offsets_.bytes(); }

   private:
    // Layers of emitter k that have left by `time`: t_k <= time for k = 0, 1, ..., at most all.
    std::uint32_t layers_due(std::size_t k, double time) const {
        const EmitterWindow& e = emitters_[k];
        if (time < e.start) return 0;
        // A layer due at the step's end to rounding counts as due (1e-9 of an interval).
        const double due = std::floor((time - e.start) / e.interval + 1e-9) + 1;
        return due >= double(layers_[k]) ? layers_[k] : static_cast<std::uint32_t>(due);
    }

    const DeviceContext& device_;
    ParticleStore& store_;
    ParticleCounts& counts_;
    Real rest_density_ = 0;
    Vec3 gravity_{0, 0, 0};
    Real nozzle_length_ = 0;  // m: the support radius h (the nozzle, above)
    Real hold_reach_ = 0;     // m: r0 / 2
    DeviceArray<Real>* temperature_ = nullptr;  // the heat's store field, with heat conduction
    std::vector<EmitterWindow> emitters_;  // base ids, layer geometry, timing
    std::vector<std::uint32_t> layers_;    // per emitter: its layers in all
    std::vector<std::uint32_t> released_;  // per emitter: layers released so far
    long released_total_ = 0;
    DeviceArray<Vec3> offsets_;  // every emitter's layer points, concatenated
};

MW_BACKEND_END
