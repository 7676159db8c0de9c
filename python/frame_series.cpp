#include "python/frame_series.hpp"

#include <cmath>
#include <cstdio>
#include <limits>

#include "apps/atomic_file.hpp"
#include "apps/vtu_writer.hpp"

namespace mw::python {

FrameSeries::FrameSeries(std::string directory) : directory_(std::move(directory)) { make_directories(directory_); }

std::string FrameSeries::write(const HostParticles& p, double time) {
    std::vector<std::size_t> shown;
    shown.reserve(p.type.size());
    for (std::size_t i = 0; i < p.type.size(); ++i)
        if (p.type[i] != kPending) shown.push_back(i);
    std::vector<Vec3> points(shown.size()), velocity(shown.size());
    std::vector<float> density(shown.size()), pressure(shown.size()), temperature;
    std::vector<std::uint8_t> type(shown.size());
    std::vector<std::int32_t> object(shown.size()), id(shown.size());
    for (std::size_t k = 0; k < shown.size(); ++k) {
        const std::size_t i = shown[k];
        points[k] = p.position[i];
        velocity[k] = p.velocity[i];
        density[k] = float(p.density[i]);
        pressure[k] = float(p.pressure[i]);
        type[k] = p.type[i];
        object[k] = p.object[i];
        id[k] = static_cast<std::int32_t>(i);
    }
    std::vector<VtuArray> arrays = {VtuArray::vector3("velocity", velocity),
                                    VtuArray::scalar("density", std::move(density)),
                                    VtuArray::scalar("pressure", std::move(pressure)),
                                    VtuArray::uint8("type", std::move(type)),
                                    VtuArray::int32("object", std::move(object)),
                                    VtuArray::int32("id", std::move(id))};
    if (!p.temperature.empty()) {
        for (const std::size_t i : shown) temperature.push_back(float(p.temperature[i]));
        arrays.push_back(VtuArray::scalar("temperature", std::move(temperature)));
    }
    char name[32];
    std::snprintf(name, sizeof name, "particles_%05d.vtu", written());
    const std::string path = directory_ + "/" + name;
    write_vtu(path, points, arrays);
    frames_.emplace_back(time, name);
    write_collection();
    return path;
}

void FrameSeries::frame_written_at(double time, double fps) {
    // The next frame time after `time`: a step longer than 1/fps skips frame times.
    const double frame_dt = 1.0 / fps;
    next_time_ = (std::floor(time / frame_dt * (1 + 1e-9)) + 1) * frame_dt;
}

void FrameSeries::write_collection() const {
    write_file_atomically(directory_ + "/particles.pvd", [&](std::ostream& out) {
        out.precision(std::numeric_limits<double>::max_digits10);
        out << "<?xml version=\"1.0\"?>\n"
               "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n  <Collection>\n";
        for (const auto& [time, file] : frames_)
            out << "    <DataSet timestep=\"" << time << "\" part=\"0\" file=\"" << file << "\"/>\n";
        out << "  </Collection>\n</VTKFile>\n";
    });
}

}  // namespace mw::python
