// Frames of one simulation in one directory, as ParaView opens them: particles_NNNNN.vtu numbered
// from 0, and particles.pvd listing each with its simulated time (open that one). A frame holds
// every particle but an emitter's not yet released, with the arrays of `meltwater run`'s frames:
// velocity, density, pressure, type, object, temperature (with heat), and id, the particle's index
// in the scene's order (the arrays of Simulation.position and the rest).
#pragma once
#include <string>
#include <utility>
#include <vector>

#include "simulation/simulation.hpp"

namespace mw::python {

class FrameSeries {
   public:
    // Creates `directory` and its parents (InputError naming it when it cannot be written).
    explicit FrameSeries(std::string directory);
    // Writes the next frame and rewrites particles.pvd; returns the frame's path.
    std::string write(const HostParticles& particles, double time);
    int written() const { return static_cast<int>(frames_.size()); }

    // The frame clock of a run that writes frames (Simulation.run(frames=...)), as the CLI's: a
    // frame at every 1/fps of simulated time, the first after the frame written at the start.
    bool due(double time) const { return time >= next_time_ * (1 - 1e-9); }
    void frame_written_at(double time, double fps);

   private:
    void write_collection() const;
    std::string directory_;
    std::vector<std::pair<double, std::string>> frames_;  // time, file name
    double next_time_ = 0;
};

}  // namespace mw::python
