// The pressure sensors module (stage "pressure_sensors", with `pressure_sensors` in the scene):
// what a pressure transducer in a tank's wall reads, the fluid's normal load on a square patch of a
// domain wall over the patch's area, every step, as stats.csv columns sensor_<name> in Pa.
//
// The load is the reaction of the pressure force PCISPH's last iteration put on the fluid from the
// wall's particles behind the patch (pcisph.hpp): on wall particle b,
//   F_b = m Σ_i ψ_b (p_i/ρ_i²) ∇W(x*_i - x_b),   ψ_b = ρ0 V_b,
// at the same predicted positions and pressures, so the wall carries exactly what the fluid felt;
// plus the momentum the walls' velocity–position correction takes from the fluid at the step's
// integration, over Δt (at rest the correction holds about a tenth of a side wall's load).
// A particle's own pressure p_i next to a wall is not the wall's load: with Akinci's boundary term
// the fluid beside a wall holds about 1.5 times the hydrostatic pressure (docs/validation.md),
// while the load it puts on the wall is the hydrostatic one.
//
// Each wall particle behind the patch counts with the share of its square of wall (the wall's
// particle spacing on a side) that lies inside the patch; the reading sums every wall layer. The
// readings are copied to the host after each step (one small copy), only in a scene with sensors.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "algorithms/boundary_volumes.hpp"
#include "algorithms/fluid.hpp"
#include "algorithms/module.hpp"
#include "algorithms/wall_correction.hpp"
#include "common/errors.hpp"
#include "simulation/simulation.hpp"

MW_BACKEND_BEGIN

template <class Kernel>
class PressureSensors final : public Module {
   public:
    PressureSensors(SimulationState<Kernel>& state, const BoundaryVolumes<Kernel>& volumes, const Fluid<Kernel>& fluid,
                    const WallCorrection& walls, const SimulationSetup& setup, bool lists)
        : state_(state), volumes_(volumes), fluid_(fluid), walls_(walls), sensors_(setup.pressure_sensors), lists_(lists) {}

    void bind(StepPlan& plan) override {
        if (active()) plan.bind("pressure_sensors", [this](StepContext& step) { measure(step); });
    }

    // The wall particles behind each patch, once: the static boundary does not move after its sort.
    void start(const StepContext& /*first*/) override {
        if (sensors_.empty()) return;
        const std::vector<Vec3> position = state_.store.position.to_host();
        const std::vector<std::uint8_t> type = state_.store.type.to_host();
        std::vector<std::uint32_t> particle, first{0};
        std::vector<Real> weight;
        std::vector<Vec3> inward;  // the wall's normal, from the fluid into the wall
        for (const PressureSensorSetup& sensor : sensors_) {
            const WallPatch patch = wall_patch(sensor, position, type, state_.fluid.kernel.h);
            if (patch.particle.empty())
                throw InputError("pressure_sensors: " + sensor.name +
                                 " has no wall particle behind it: its face of the domain has no wall (boundary.walls)");
            particle.insert(particle.end(), patch.particle.begin(), patch.particle.end());
            weight.insert(weight.end(), patch.weight.begin(), patch.weight.end());
            first.push_back(std::uint32_t(particle.size()));
            Vec3 n{0, 0, 0};
            set_component(n, sensor.axis, Real(sensor.side));
            inward.push_back(n);
        }
        device_particle_.upload(particle);
        device_weight_.upload(weight);
        device_first_.upload(first);
        device_inward_.upload(inward);
        device_load_.resize(particle.size());
        device_reading_.resize(sensors_.size());
        area_.clear();
        // In 2D a patch is a segment of a wall's line, and the load one per unit depth.
        const bool plane = state_.params.dimensions == 2;
        for (const PressureSensorSetup& sensor : sensors_)
            area_.push_back(plane ? double(sensor.size) : double(sensor.size) * double(sensor.size));
    }

    std::size_t bytes() const override {
        return device_particle_.size() * sizeof(std::uint32_t) + device_first_.size() * sizeof(std::uint32_t) +
               device_load_.size() * sizeof(Real) + device_reading_.size() * sizeof(Real) +
               device_inward_.size() * sizeof(Vec3) + device_weight_.size() * sizeof(Real);
    }

    void measure(const StepContext& step) {
        const FluidConstants<Kernel> c = state_.fluid;
        const GridView grid = step.neighbors.grid;
        const Real list_radius2 = lists_ ? c.kernel.h * c.kernel.h : Real(0);
        const View<const Vec3> position = state_.store.position.cview(), velocity = state_.store.velocity.cview(),
                               predicted = fluid_.predicted(), pressure_acc = fluid_.last_pressure_acceleration();
        const View<const Real> volume = volumes_.volumes(), pressure_term = fluid_.pressure_term();
        const Vec3* nonpressure = step.nonpressure;
        const WallContact walls = walls_.walls();
        const std::uint32_t* particle = device_particle_.view().data();
        const std::uint32_t* first = device_first_.view().data();
        const Real* weight = device_weight_.view().data();
        const Vec3* inward = device_inward_.view().data();
        Real* load = device_load_.view().data();
        Real* reading = device_reading_.view().data();
        const std::uint32_t sensor_count = std::uint32_t(sensors_.size());
        const Real scale = c.mass * c.rest_density, dt = step.dt, correction_scale = c.mass / step.dt;
        // Each wall particle's load along its sensor's inward normal.
        parallel_for(state_.device, "pressure_sensor_load", device_particle_.size(), [=] MW_HD(std::size_t k) {
            std::uint32_t s = 0;
            while (s + 1 < sensor_count && first[s + 1] <= k) ++s;
            const std::uint32_t b = particle[k];
            const Vec3 xb = position[b];
            Vec3 pressure_sum{0, 0, 0}, impulse_sum{0, 0, 0};
            grid.for_each_fluid(xb, [&](std::uint32_t i) {
                // The pairs PCISPH's pressure force summed: in grid mode every fluid particle in the
                // cells around, with lists only those within h at the step's start (neighbor_list.hpp).
                if (!(list_radius2 > Real(0)) || norm2(position[i] - xb) < list_radius2) {
                    const Vec3 r = predicted[i] - xb;
                    pressure_sum += pressure_term[i] * c.kernel.grad_W_r2(r, norm2(r));
                }
                // The walls' correction in "integrate" takes the velocity into the wall away: that
                // momentum is load too. Each wall particle takes the share V_b W_ib / Σ_b' V_b' W_ib'
                // of it, so the wall as a whole takes all of it. (Recomputed for each wall particle
                // the fluid particle is near: a handful, and only at a sensor.)
                const Real w = c.kernel.W_r2(norm2(position[i] - xb));
                if (!(w > Real(0))) return;
                const Vec3 a = (nonpressure ? nonpressure[i] : c.gravity) + pressure_acc[i];
                Vec3 x = position[i], v = velocity[i];
                integrate_particle(x, v, a, dt, walls);
                const Vec3 dv = v - (velocity[i] + dt * a);
                if (dv.x == Real(0) && dv.y == Real(0) && dv.z == Real(0)) return;
                Real wall_sum = 0;
                grid.for_each_static(position[i], [&](std::uint32_t o) {
                    wall_sum += volume[o] * c.kernel.W_r2(norm2(position[i] - position[o]));
                });
                if (wall_sum > Real(0)) impulse_sum += (w / wall_sum) * dv;
            });
            load[k] = weight[k] * volume[b] * (scale * dot(pressure_sum, inward[s]) - correction_scale * dot(impulse_sum, inward[s]));
        });
        // Each sensor's sum, in a fixed order (results do not depend on the thread count).
        parallel_for(state_.device, "pressure_sensor_sum", sensors_.size(), [=] MW_HD(std::size_t s) {
            Real total = 0;
            for (std::uint32_t k = first[s]; k < first[s + 1]; ++k) total += load[k];
            reading[s] = total;
        });
        step_measured_ = true;
    }

    void report_columns(std::vector<std::string>& names) const override {
        if (!active()) return;
        for (const PressureSensorSetup& sensor : sensors_) names.push_back("sensor_" + sensor.name);
    }
    // Pa: the load over the patch's area.
    void report(std::vector<double>& values) const override {
        if (!active()) return;
        std::vector<Real> load(sensors_.size(), Real(0));
        if (step_measured_) device_reading_.download(load.data(), load.size());
        for (std::size_t s = 0; s < sensors_.size(); ++s) values.push_back(double(load[s]) / area_[s]);
    }

   private:
    // A patch's wall particles, each weighted by how much of the wall it stands for lies in the
    // square: a particle stands for a square of the wall's particle spacing around it, so a patch
    // that cuts between particles reads the load on its own area, whatever the alignment.
    struct WallPatch {
        std::vector<std::uint32_t> particle;
        std::vector<Real> weight;
    };
    static WallPatch wall_patch(const PressureSensorSetup& sensor, const std::vector<Vec3>& position,
                                const std::vector<std::uint8_t>& type, Real reach) {
        const int a = sensor.axis, t1 = (a + 1) % 3, t2 = (a + 2) % 3;
        const double half = 0.5 * double(sensor.size);
        // The wall behind the patch and a support radius around it, as (depth, t1, t2).
        std::vector<std::uint32_t> near;
        std::vector<std::array<double, 3>> local;
        for (std::size_t b = 0; b < position.size(); ++b) {
            if (type[b] != kStaticBoundary) continue;
            const Vec3 d = position[b] - sensor.center;
            const double depth = double(component(d, a)) * sensor.side, u = component(d, t1), v = component(d, t2);
            if (depth < 0 || depth > double(reach) || std::abs(u) > half + double(reach) ||
                std::abs(v) > half + double(reach))
                continue;
            near.push_back(std::uint32_t(b));
            local.push_back({depth, u, v});
        }
        // The spacing: the median distance from a particle to its nearest neighbour in its layer,
        // over a sample of up to 64 of them (a patch as large as the floor holds thousands).
        std::vector<double> nearest;
        const std::size_t sample_step = std::max<std::size_t>(1, local.size() / 64);
        for (std::size_t k = 0; k < local.size(); k += sample_step) {
            double best = 1e300;
            for (std::size_t j = 0; j < local.size(); ++j)
                if (j != k && std::abs(local[j][0] - local[k][0]) < 1e-6 * (1 + double(reach)))
                    best = std::min(best, std::hypot(local[j][1] - local[k][1], local[j][2] - local[k][2]));
            if (best < 1e300) nearest.push_back(best);
        }
        WallPatch patch;
        if (nearest.empty()) return patch;
        std::nth_element(nearest.begin(), nearest.begin() + long(nearest.size() / 2), nearest.end());
        const double spacing = nearest[nearest.size() / 2];
        auto overlap = [&](double x) {  // of [x - spacing/2, x + spacing/2] with [-half, half], over spacing
            const double lo = std::max(x - 0.5 * spacing, -half), hi = std::min(x + 0.5 * spacing, half);
            return hi > lo ? (hi - lo) / spacing : 0.0;
        };
        for (std::size_t k = 0; k < local.size(); ++k) {
            const double w = overlap(local[k][1]) * overlap(local[k][2]);
            if (w <= 0) continue;
            patch.particle.push_back(near[k]);
            patch.weight.push_back(Real(w));
        }
        return patch;
    }

    bool active() const { return state_.has_fluid && !sensors_.empty(); }
    static Real component(Vec3 v, int a) { return a == 0 ? v.x : (a == 1 ? v.y : v.z); }
    static void set_component(Vec3& v, int a, Real x) { (a == 0 ? v.x : (a == 1 ? v.y : v.z)) = x; }

    SimulationState<Kernel>& state_;
    const BoundaryVolumes<Kernel>& volumes_;
    const Fluid<Kernel>& fluid_;
    const WallCorrection& walls_;
    std::vector<PressureSensorSetup> sensors_;
    bool lists_ = false;
    DeviceArray<Real> device_reading_;            // [sensor], N
    DeviceArray<Real> device_load_;               // [wall particle under a sensor], N
    DeviceArray<std::uint32_t> device_particle_;  // store index of each wall particle under a sensor
    DeviceArray<Real> device_weight_;             // the share of its square inside the patch
    DeviceArray<std::uint32_t> device_first_;     // sensor s's particles: [first[s], first[s + 1])
    DeviceArray<Vec3> device_inward_;             // [sensor]: the wall's normal, from the fluid into it
    std::vector<double> area_;                    // [sensor], m²
    bool step_measured_ = false;
};

MW_BACKEND_END
