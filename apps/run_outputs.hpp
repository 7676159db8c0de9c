// What `meltwater run` records besides its frames (apps/frame_writer.hpp), each file atomically:
//   stats.csv                    one row per step
//   summary.json                 the run in one object, the resolved scene included
// and the clearing of an earlier run's outputs from the directory.
#pragma once
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "simulation/simulation.hpp"
#include "apps/scene.hpp"

namespace mw {

// Frames of an earlier run into the same directory would mix with this run's, or sit next to a
// summary that says it wrote none: remove them (every file is_frame_file names, and the
// temporaries of a killed run), and frames/ itself when that leaves it empty. Run before
// every run, with or without frames. A run resumed in its checkpoint's directory keeps the
// frames numbered below `keep_frames_below` (those written before the checkpoint) and the earlier
// run's records; any other run removes those too (stats.csv, summary.json, checkpoint.mwc), so
// that a run killed early never leaves an earlier run's "completed" summary beside its frames.
struct RemovedOutputs {
    int frames = 0;                    // frame numbers of which a file was removed
    std::vector<std::string> records;  // the records removed, by name
};
RemovedOutputs remove_earlier_outputs(const std::string& out_dir, int keep_frames_below, bool keep_records);

// The rows of an earlier stats.csv at `path` up to and including step `last_step`. A run resumed
// in its checkpoint's directory continues the table from there, so the rows must run one step
// after another up to `last_step` exactly, under `header`; when they do not (no file, other
// columns, a missing or damaged row), `rows` is empty and `problem` says why.
struct EarlierStatsRows {
    std::string rows;
    std::string problem;
};
EarlierStatsRows stats_rows_up_to(const std::string& path, const std::string& header, long last_step);

// Per-step statistics: each row is formatted once, when added, and the whole table is rewritten
// atomically (so stats.csv is always whole). The numbers the summary needs are kept as columns.
class StatsTable {
   public:
    // `columns`: the modules' own columns (StepReport::column_names), after the fluid's and before
    // the stages' times.
    StatsTable(std::vector<std::string> stage_names, std::vector<std::string> columns);
    void add(const StepReport& report);
    // Rows of the run this one resumes (stats_rows_up_to), written before this run's; the figures
    // below cover this run's rows only.
    void keep_earlier_rows(std::string rows) { earlier_rows_ = std::move(rows); }
    std::string header() const;
    void write(const std::string& path) const;

    std::size_t rows() const { return total_ms_.size(); }
    const std::vector<std::string>& stage_names() const { return stages_; }
    // Medians of each stage's ms and of the total, in stage order, then "total".
    std::vector<double> median_stage_ms() const;
    double median_total_ms() const;
    double density_error_avg() const;  // mean over steps of the per-step average
    double density_error_max() const;  // max over steps of the per-step maximum
    double iterations_avg() const;
    int iterations_max() const;
    long retried_steps() const { return retried_steps_; }  // steps retried at a smaller dt (CFL mode)
    long diverged_steps() const { return diverged_steps_; }  // steps whose last PCISPH try diverged
    // steps whose last PCISPH try ran out of iterations above the tolerance
    long unconverged_steps() const { return unconverged_steps_; }
    // The fastest particle, fluid or solid, over this run's steps, m/s.
    double peak_speed() const { return peak_speed_; }
    double sum_total_ms() const;
    // The modules' columns: whether the table has one, and its value after this run's first step
    // and after its last (heat_content: the heat's conservation; melted, emitted: the counts).
    bool has_column(const std::string& name) const;
    double column_first(const std::string& name) const;
    double column_last(const std::string& name) const;

   private:
    std::size_t column_index(const std::string& name) const;  // columns_.size() when absent
    std::vector<std::string> stages_;
    std::vector<std::string> columns_;
    std::vector<double> column_first_, column_last_;
    double peak_speed_ = 0;
    std::string earlier_rows_;                   // a resumed run's rows from before its checkpoint
    std::string csv_rows_;                       // every row so far, as written to stats.csv
    std::vector<std::vector<double>> stage_ms_;  // [stage][row]
    std::vector<double> total_ms_, error_avg_, error_max_;
    std::vector<int> iterations_;
    long retried_steps_ = 0, diverged_steps_ = 0, unconverged_steps_ = 0;
};

struct RunSummary {
    std::string status = "completed";  // or "failed"
    std::string error;
    std::string backend, device;
    int threads = 0;
    long steps = 0;
    double simulated_time = 0;
    double wall_seconds = 0;
    long lost_particles = 0;
    ParticleCounts particles;         // at the start
    // At the end, fluid released by emitters and melted from solids included (none: unknown).
    std::optional<ParticleCounts> particles_at_end;
    long fluid_carved = 0;  // fluid particles left out where static boxes and objects stand
    std::size_t device_bytes = 0;
    double speed_limit = 0;  // m/s: the runaway guard's (speed_limit.hpp); 0 when there is none
    int frames = 0;
    // Surface reconstruction (output.formats "surface"): meshes written, the median time one took
    // (colour field, copy and meshing; writing the file aside), and the last one's triangles.
    int surfaces = 0;
    double surface_ms_median = 0;
    double surface_field_ms_median = 0;  // of which the colour field (grid build, field, host copy)
    long surface_triangles_last = 0;
    // Previews (output.formats "preview"): pictures written, the median time one took.
    int previews = 0;
    double preview_ms_median = 0;
    // Moving 2D objects (apps/fluid_inside_objects.hpp): frames counted, and the fluid particles
    // inside their outlines, all objects together: the most at one frame, the mean, the last.
    int inside_frames = 0;
    long fluid_inside_max = 0, fluid_inside_last = 0;
    double fluid_inside_sum = 0;
    std::string stop_condition;  // "steps N" or "time T s"
    std::vector<std::string> warnings;  // about the scene, given before the run (Scene::kernel_warning)
    // A resumed run: the checkpoint it started from, and that checkpoint's step and time.
    std::string resumed_from;
    long resumed_step = 0;
    double resumed_time = 0;
    // The last checkpoint this run wrote ("" if none), and its step.
    std::string checkpoint;
    long checkpoint_step = 0;
    // Outputs flushed to disk (frames, stats.csv, checkpoints; apps/atomic_file.hpp), and the
    // seconds their fsyncs and renames took.
    long synced_files = 0;
    double sync_seconds = 0;
};

double median_of(std::vector<double> values);  // 0 for none

void write_summary(const std::string& path, const RunSummary& summary, const StatsTable& stats, const Scene& scene);

}  // namespace mw
