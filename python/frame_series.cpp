#include "python/frame_series.hpp"

#include <cmath>

namespace mw::python {

namespace {
// Particles and objects only: surfaces, grids and pictures need the simulation's backend and
// settings that a frame written from Python does not take.
FrameFormats particle_formats(FrameFormats f) {
    FrameFormats out;
    out.vtu = f.vtu || !f.ply;
    out.ply = f.ply;
    return out;
}
}  // namespace

FrameSeries::FrameSeries(const std::string& directory, FrameFormats formats, const std::vector<SolidSetup>& solids)
    : writer_(directory, particle_formats(formats)) {
    writer_.set_objects(solids);
}

std::string FrameSeries::write(const HostParticles& p, double time) { return writer_.write(written(), p, time); }

void FrameSeries::frame_written_at(double time, double fps) {
    // The next frame time after `time`: a step longer than 1/fps skips frame times.
    const double frame_dt = 1.0 / fps;
    next_time_ = (std::floor(time / frame_dt * (1 + 1e-9)) + 1) * frame_dt;
}

}  // namespace mw::python
