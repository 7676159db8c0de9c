#include "apps/run_outputs.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <set>

#include "apps/atomic_file.hpp"
#include "apps/checkpoint_file.hpp"
#include "apps/frame_writer.hpp"
#include "common/errors.hpp"

namespace mw {

double median_of(std::vector<double> v) {
    if (v.empty()) return 0;
    std::sort(v.begin(), v.end());
    const std::size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

namespace {
// JSON numbers must be finite; a NaN would make nlohmann write `null` anyway, say so explicitly.
SceneJson finite_or_null(double v) { return std::isfinite(v) ? SceneJson(v) : SceneJson(nullptr); }
}  // namespace

RemovedOutputs remove_earlier_outputs(const std::string& out_dir, int keep_frames_below, bool keep_records) {
    RemovedOutputs removed;
    std::set<int> frame_numbers;
    const std::string frames_dir = out_dir + "/frames";
    std::error_code error;
    if (std::filesystem::is_directory(frames_dir, error)) {
        for (const auto& entry : std::filesystem::directory_iterator(frames_dir, error)) {
            const std::string name = entry.path().filename().string();
            // A frame's temporary (NAME.tmp.PID) is left only by a run killed mid-write.
            const std::size_t tmp = name.find(".tmp.");
            const std::string frame_name = tmp == std::string::npos ? name : name.substr(0, tmp);
            const int number = frame_file_number(frame_name);
            const bool frame = number >= 0 || is_frame_file(frame_name);
            const bool kept = tmp == std::string::npos && number >= 0 && number < keep_frames_below;
            if ((frame && !kept) || frame_name == "particles.pvd") std::filesystem::remove(entry.path(), error);
            if (frame && !kept && tmp == std::string::npos && number >= 0) frame_numbers.insert(number);
        }
        std::filesystem::remove(frames_dir, error);  // only if now empty: a user's own files stay
    }
    removed.frames = static_cast<int>(frame_numbers.size());
    // The temporaries of stats.csv, summary.json and the checkpoint in DIR itself, and the records.
    for (const auto& entry : std::filesystem::directory_iterator(out_dir, error)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind("stats.csv.tmp.", 0) == 0 || name.rfind("summary.json.tmp.", 0) == 0 ||
            name.rfind(std::string(kCheckpointFileName) + ".tmp.", 0) == 0)
            std::filesystem::remove(entry.path(), error);
    }
    if (!keep_records)
        for (const std::string name : {"summary.json", "stats.csv", kCheckpointFileName})
            if (std::filesystem::is_regular_file(out_dir + "/" + name, error) &&
                std::filesystem::remove(out_dir + "/" + name, error))
                removed.records.push_back(name);
    return removed;
}

StatsTable::StatsTable(std::vector<std::string> stage_names, std::vector<std::string> columns)
    : stages_(std::move(stage_names)),
      columns_(std::move(columns)),
      column_first_(columns_.size(), 0.0),
      column_last_(columns_.size(), 0.0),
      stage_ms_(stages_.size()) {}

std::size_t StatsTable::column_index(const std::string& name) const {
    return std::size_t(std::find(columns_.begin(), columns_.end(), name) - columns_.begin());
}
bool StatsTable::has_column(const std::string& name) const { return column_index(name) < columns_.size(); }
double StatsTable::column_first(const std::string& name) const {
    const std::size_t k = column_index(name);
    return k < columns_.size() ? column_first_[k] : 0.0;
}
double StatsTable::column_last(const std::string& name) const {
    const std::size_t k = column_index(name);
    return k < columns_.size() ? column_last_[k] : 0.0;
}

void StatsTable::add(const StepReport& r) {
    char buffer[256];
    std::snprintf(buffer, sizeof buffer, "%ld,%.9g,%.9g,%d,%.6g,%.6g,%.6g,%.6g,%ld,%d,%d,%d", r.step, r.time, r.dt,
                  r.iterations, r.density_error_avg, r.density_error_max, r.max_speed, r.kinetic_energy,
                  r.lost_particles, r.retries, r.diverged ? 1 : 0, r.unconverged ? 1 : 0);
    csv_rows_ += buffer;
    // Counts print as integers in %.9g (up to 1e9), the heat content with 9 digits.
    for (std::size_t k = 0; k < columns_.size(); ++k) {
        const double value = k < r.columns.size() ? r.columns[k] : 0.0;
        std::snprintf(buffer, sizeof buffer, ",%.9g", value);
        csv_rows_ += buffer;
        if (total_ms_.empty()) column_first_[k] = value;
        column_last_[k] = value;
    }
    for (std::size_t s = 0; s < stages_.size(); ++s) {
        const double ms = s < r.stage_ms.size() ? r.stage_ms[s] : 0.0;
        std::snprintf(buffer, sizeof buffer, ",%.4f", ms);
        csv_rows_ += buffer;
        stage_ms_[s].push_back(ms);
    }
    std::snprintf(buffer, sizeof buffer, ",%.4f\n", r.total_ms);
    csv_rows_ += buffer;
    total_ms_.push_back(r.total_ms);
    error_avg_.push_back(r.density_error_avg);
    error_max_.push_back(r.density_error_max);
    iterations_.push_back(r.iterations);
    retried_steps_ += r.retries > 0;
    peak_speed_ = std::max(peak_speed_, std::max(r.max_speed, r.solid_max_speed));
    diverged_steps_ += r.diverged;
    unconverged_steps_ += r.unconverged;
}

std::string StatsTable::header() const {
    std::string h =
        "step,time,dt,iterations,density_error_avg,density_error_max,max_speed,kinetic_energy,lost_particles,"
        "dt_retries,diverged,unconverged";
    for (const auto& c : columns_) h += "," + c;
    for (const auto& s : stages_) h += ",ms_" + s;
    return h + ",ms_total";
}

void StatsTable::write(const std::string& path) const {
    write_file_atomically(path, [&](std::ostream& out) { out << header() << '\n' << earlier_rows_ << csv_rows_; });
}

EarlierStatsRows stats_rows_up_to(const std::string& path, const std::string& header, long last_step) {
    if (last_step <= 0) return {};
    std::ifstream in(path);
    std::string line;
    if (!in) return {"", path + " is missing"};
    if (!std::getline(in, line) || line != header) return {"", path + " has other columns than this run writes"};
    std::string rows;
    long previous = -1;
    for (long number = 2; previous < last_step && std::getline(in, line); ++number) {
        char* end = nullptr;
        const long step = std::strtol(line.c_str(), &end, 10);
        if (end == line.c_str() || *end != ',')
            return {"", path + " has a damaged row (line " + std::to_string(number) + ")"};
        if (step > last_step) break;
        if (previous >= 0 && step != previous + 1)
            return {"", path + " jumps from step " + std::to_string(previous) + " to step " + std::to_string(step)};
        rows += line + '\n';
        previous = step;
    }
    if (previous != last_step)
        return {"", path + (previous < 0 ? std::string(" holds no rows up to") : " ends at step " + std::to_string(previous) +
                                                                                 ", before") +
                        " the checkpoint's step " + std::to_string(last_step)};
    return {rows, ""};
}

std::vector<double> StatsTable::median_stage_ms() const {
    std::vector<double> out;
    for (const auto& column : stage_ms_) out.push_back(median_of(column));
    return out;
}

double StatsTable::median_total_ms() const { return median_of(total_ms_); }

double StatsTable::density_error_avg() const {
    if (error_avg_.empty()) return 0;
    double s = 0;
    for (double e : error_avg_) s += e;
    return s / double(error_avg_.size());
}

double StatsTable::density_error_max() const {
    double m = 0;
    for (double e : error_max_) m = std::max(m, e);
    return m;
}

double StatsTable::iterations_avg() const {
    if (iterations_.empty()) return 0;
    double s = 0;
    for (int i : iterations_) s += i;
    return s / double(iterations_.size());
}

int StatsTable::iterations_max() const {
    int m = 0;
    for (int i : iterations_) m = std::max(m, i);
    return m;
}

double StatsTable::sum_total_ms() const {
    double s = 0;
    for (double t : total_ms_) s += t;
    return s;
}

void write_summary(const std::string& path, const RunSummary& run, const StatsTable& stats, const Scene& scene) {
    SceneJson j;
    j["status"] = run.status;
    if (!run.error.empty()) j["error"] = run.error;
    j["backend"] = run.backend;
    j["device"] = run.device;
    if (run.backend == "openmp" && run.threads > 0) j["threads"] = run.threads;
    j["scene_name"] = scene.name;
    j["scene_source"] = scene.source;
    j["stop_condition"] = run.stop_condition;
    j["steps"] = run.steps;
    j["simulated_time"] = finite_or_null(run.simulated_time);
    j["wall_seconds"] = run.wall_seconds;
    const auto counts = [](const ParticleCounts& c) {
        SceneJson by_type;
        for (int t = 0; t < kParticleTypeCount; ++t) by_type[particle_type_name(t)] = c.by_type[t];
        by_type["total"] = c.total();
        return by_type;
    };
    j["particles"] = counts(run.particles);
    if (run.particles_at_end) j["particles_at_end"] = counts(*run.particles_at_end);
    j["fluid_carved"] = run.fluid_carved;
    j["lost_particles"] = run.lost_particles;
    SceneJson ms;
    const std::vector<double> medians = stats.median_stage_ms();
    for (std::size_t s = 0; s < medians.size(); ++s) ms[stats.stage_names()[s]] = medians[s];
    ms["total"] = stats.median_total_ms();
    j["ms_per_step"] = ms;
    if (scene.writes_surface())
        j["surface"] = {{"meshes", run.surfaces},
                        {"ms_per_mesh", run.surface_ms_median},
                        {"field_ms_per_mesh", run.surface_field_ms_median},
                        {"triangles_last", run.surface_triangles_last}};
    if (run.inside_frames > 0)
        j["fluid_inside_objects"] = {{"frames", run.inside_frames},
                                     {"max", run.fluid_inside_max},
                                     {"mean", run.fluid_inside_sum / run.inside_frames},
                                     {"last", run.fluid_inside_last}};
    if (scene.frame_formats().preview) j["preview"] = {{"pictures", run.previews}, {"ms_per_picture", run.preview_ms_median}};
    const double step_seconds = stats.sum_total_ms() / 1000.0;
    j["particle_steps_per_second"] =
        step_seconds > 0 ? double(run.particles.total()) * double(stats.rows()) / step_seconds : 0.0;
    j["density_error"] = {{"avg", finite_or_null(stats.density_error_avg())},
                          {"max", finite_or_null(stats.density_error_max())}};
    j["iterations"] = {{"avg", stats.iterations_avg()}, {"max", stats.iterations_max()}};
    j["retried_steps"] = stats.retried_steps();
    j["diverged_steps"] = stats.diverged_steps();
    j["unconverged_steps"] = stats.unconverged_steps();
    // The fastest particle of the run against the runaway guard's limit (null: no guard).
    j["speed"] = {{"peak", finite_or_null(stats.peak_speed())},
                  {"limit", run.speed_limit > 0 ? SceneJson(run.speed_limit) : SceneJson(nullptr)}};
    // Heat conduction: the heat content (stats.csv) should stay constant; its change over the run.
    if (stats.has_column("heat_content") && stats.rows() > 0) {
        const double first = stats.column_first("heat_content"), last = stats.column_last("heat_content");
        j["heat_content"] = {{"after_first_step", finite_or_null(first)},
                             {"at_end", finite_or_null(last)},
                             {"relative_change", finite_or_null(first != 0 ? (last - first) / std::fabs(first) : 0.0)}};
    }
    // Melting: the particles that have left their objects for the fluid by the end of the run.
    if (stats.has_column("melted") && stats.rows() > 0) j["melted_particles"] = long(stats.column_last("melted"));
    // Emitters: the particles released by the end of the run.
    if (stats.has_column("emitted") && stats.rows() > 0) j["emitted_particles"] = long(stats.column_last("emitted"));
    j["device_bytes"] = run.device_bytes;
    j["bytes_per_particle"] =
        run.particles.total() > 0 ? double(run.device_bytes) / double(run.particles.total()) : 0.0;
    j["frames"] = run.frames;
    j["disk_sync"] = {{"files", run.synced_files},
                      {"seconds", run.sync_seconds},
                      {"fraction_of_wall", run.wall_seconds > 0 ? run.sync_seconds / run.wall_seconds : 0.0}};
    j["warnings"] = run.warnings;
    if (!run.resumed_from.empty())
        j["resumed_from"] = {{"checkpoint", run.resumed_from}, {"step", run.resumed_step},
                             {"time", finite_or_null(run.resumed_time)}};
    if (!run.checkpoint.empty()) j["checkpoint"] = {{"path", run.checkpoint}, {"step", run.checkpoint_step}};
    j["scene"] = scene.resolved;
    // A path given on the command line may hold bytes that are not UTF-8: replaced, never fatal.
    const std::string text = j.dump(2, ' ', false, SceneJson::error_handler_t::replace) + "\n";
    write_file_atomically(path, [&](std::ostream& out) { out << text; });
}

}  // namespace mw
