// Frames of one simulation in one directory, written as `meltwater run` writes them
// (apps/frame_writer.hpp): particles_NNNNN.vtu numbered from 0 (and .ply with output.formats
// "ply"), the static boundary once in static_boundary.vtu, each object's mesh, and particles.pvd
// listing each frame with its simulated time (open that one). A frame's `id` is the particle's
// index in the scene's order (the arrays of Simulation.position and the rest).
#pragma once
#include <string>
#include <vector>

#include "apps/frame_writer.hpp"
#include "simulation/simulation.hpp"

namespace mw::python {

class FrameSeries {
   public:
    // Creates `directory` and its parents (InputError naming it when it cannot be written).
    // `formats`: the scene's; the particles go as VTU when it names neither "vtu" nor "ply".
    FrameSeries(const std::string& directory, FrameFormats formats, const std::vector<SolidSetup>& solids);
    // Writes the next frame and rewrites particles.pvd; returns the path of its particles.
    std::string write(const HostParticles& particles, double time);
    int written() const { return writer_.written(); }

    // The frame clock of a run that writes frames (Simulation.run(frames=...)), as the CLI's: a
    // frame at every 1/fps of simulated time, the first after the frame written at the start.
    bool due(double time) const { return time >= next_time_ * (1 - 1e-9); }
    void frame_written_at(double time, double fps);

   private:
    FrameWriter writer_;
    double next_time_ = 0;
};

}  // namespace mw::python
