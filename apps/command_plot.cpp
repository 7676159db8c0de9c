// `meltwater plot RUN_DIR`: a run's stats.csv drawn as one PNG of panels against simulated time
// (step size, PCISPH iterations, density error, speeds, kinetic energy, stage times, and the
// modules' columns where the run has them), titled from its summary.json, so that a finished,
// running or failed run can be judged at a glance. The drawing is render/plot.hpp's.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

#include "apps/atomic_file.hpp"
#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "common/errors.hpp"
#include "render/plot.hpp"

namespace mw {

namespace {

namespace fs = std::filesystem;

// stats.csv by column: each column's values, one per step, in the file's order.
struct StatsTable {
    std::vector<std::string> names;
    std::vector<std::vector<double>> columns;
    std::size_t rows() const { return columns.empty() ? 0 : columns.front().size(); }
    // The column called `name`, or null where the run has none (a module that was off).
    const std::vector<double>* column(const std::string& name) const {
        const auto it = std::find(names.begin(), names.end(), name);
        return it == names.end() ? nullptr : &columns[std::size_t(it - names.begin())];
    }
};

std::vector<std::string> split_cells(const std::string& line) {
    std::vector<std::string> cells;
    std::string cell;
    std::istringstream in(line);
    while (std::getline(in, cell, ',')) cells.push_back(cell);
    if (!line.empty() && line.back() == ',') cells.emplace_back();  // getline drops a last empty cell
    return cells;
}

// A cell's number; "nan" and "inf" (what a diverged step writes) are numbers too, to be skipped
// when drawn.
double parse_cell(const std::string& cell, const std::string& where, const std::string& column) {
    const char* begin = cell.c_str();
    char* end = nullptr;
    const double value = std::strtod(begin, &end);
    if (cell.empty() || end != begin + cell.size())
        throw InputError(where + ", column " + column + ": '" + cell + "' is not a number");
    return value;
}

StatsTable read_stats(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw InputError("cannot open " + path);
    StatsTable table;
    std::string line;
    if (!std::getline(in, line) || line.empty() || line == "\r")
        throw InputError(path + " is empty (no header line)");
    if (line.back() == '\r') line.pop_back();
    table.names = split_cells(line);
    table.columns.assign(table.names.size(), {});
    for (const char* required : {"step", "time"})
        if (!table.column(required))
            throw InputError(path + ": the header has no '" + std::string(required) + "' column (is it a stats.csv?)");
    for (long number = 2; std::getline(in, line); ++number) {
        if (!line.empty() && line.back() == '\r') line.pop_back();
        if (line.empty()) continue;
        const std::string where = path + " line " + std::to_string(number);
        const std::vector<std::string> cells = split_cells(line);
        if (cells.size() != table.names.size())
            throw InputError(where + ": " + std::to_string(cells.size()) + " values where the header names " +
                             std::to_string(table.names.size()));
        for (std::size_t c = 0; c < cells.size(); ++c)
            table.columns[c].push_back(parse_cell(cells[c], where, table.names[c]));
    }
    return table;
}

// summary.json, or null where there is none yet (a run still going) or it cannot be read; the
// plot is still drawn then, and `note` says why the title has no status.
nlohmann::json read_summary(const std::string& path, std::string* note) {
    std::error_code error;
    if (!fs::exists(path, error)) {
        *note = "no summary.json (still running?)";
        return nullptr;
    }
    std::ifstream in(path, std::ios::binary);
    nlohmann::json summary = nlohmann::json::parse(in, nullptr, false);
    if (summary.is_discarded() || !summary.is_object()) {
        *note = "summary.json unreadable";
        std::fprintf(stderr, "meltwater: warning: %s is not a JSON object; the plot has no status\n",
                     printable(path).c_str());
        return nullptr;
    }
    return summary;
}

std::string json_text(const nlohmann::json& j, const char* key) {
    return j.is_object() && j.contains(key) && j[key].is_string() ? j[key].get<std::string>() : "";
}
double json_number(const nlohmann::json& j, const char* key) {
    return j.is_object() && j.contains(key) && j[key].is_number() ? j[key].get<double>() : NAN;
}

// The column scaled by `factor` (ms from s, percent from a fraction); empty where it is absent.
std::vector<double> scaled(const StatsTable& stats, const std::string& name, double factor) {
    const std::vector<double>* column = stats.column(name);
    std::vector<double> out;
    if (column)
        for (const double v : *column) out.push_back(v * factor);
    return out;
}

void add_series(plot::Panel& panel, const StatsTable& stats, const std::string& column, const std::string& label,
                Rgb colour, double factor = 1) {
    if (!stats.column(column)) return;
    panel.series.push_back({label, *stats.column("time"), scaled(stats, column, factor), colour});
}

plot::Panel make_panel(const std::string& title, const std::string& empty_text) {
    plot::Panel panel;
    panel.title = title;
    panel.empty_text = empty_text;
    return panel;
}

// Time per step: the stages that took longest on average as lines of their own, the rest as one
// "other" line, and the total.
plot::Panel stage_panel(const StatsTable& stats, const std::string& empty_text) {
    constexpr std::size_t kStagesShown = 4;
    plot::Panel panel = make_panel("time per step (ms)", empty_text);
    std::vector<std::pair<double, std::string>> stages;  // mean ms, column
    for (const std::string& name : stats.names) {
        if (name.rfind("ms_", 0) != 0 || name == "ms_total") continue;
        double sum = 0;
        long count = 0;
        for (const double v : *stats.column(name))
            if (std::isfinite(v)) sum += v, ++count;
        stages.emplace_back(count ? sum / double(count) : 0.0, name);
    }
    std::stable_sort(stages.begin(), stages.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
    // One stage left over is shown as itself: an "other" line of one would hide its name.
    const std::size_t shown = stages.size() <= kStagesShown + 1 ? stages.size() : kStagesShown;
    for (std::size_t k = 0; k < shown; ++k)
        add_series(panel, stats, stages[k].second, stages[k].second.substr(3), plot::palette(int(k)));
    if (shown < stages.size()) {
        std::vector<double> other(stats.rows(), 0.0);
        for (std::size_t k = shown; k < stages.size(); ++k)
            for (std::size_t row = 0; row < stats.rows(); ++row) other[row] += (*stats.column(stages[k].second))[row];
        panel.series.push_back({"other " + std::to_string(stages.size() - shown) + " stages", *stats.column("time"),
                                other, plot::palette(5)});
    }
    add_series(panel, stats, "ms_total", "total", {30, 30, 30});
    return panel;
}

// Particles lost from the domain, melted and emitted: only where the run has any of them.
void add_count_panel(std::vector<plot::Panel>& panels, const StatsTable& stats, const std::string& empty_text) {
    plot::Panel panel = make_panel("particles (count)", empty_text);
    const auto any_nonzero = [&](const char* name) {
        const std::vector<double>* column = stats.column(name);
        return column && std::any_of(column->begin(), column->end(), [](double v) { return v != 0; });
    };
    if (any_nonzero("lost_particles")) add_series(panel, stats, "lost_particles", "lost", plot::palette(1));
    if (stats.column("melted")) add_series(panel, stats, "melted", "melted", plot::palette(0));
    if (stats.column("emitted")) add_series(panel, stats, "emitted", "emitted", plot::palette(2));
    if (!panel.series.empty()) panels.push_back(panel);
}

// The pressure sensors' readings (stats.csv sensor_NAME, Pa), one line each: only where the scene
// has sensors. The palette has seven colours: further sensors are left to the CSV.
void add_sensor_panel(std::vector<plot::Panel>& panels, const StatsTable& stats, const std::string& empty_text) {
    plot::Panel panel = make_panel("wall pressure at the sensors (kPa)", empty_text);
    int shown = 0;
    for (const std::string& name : stats.names)
        if (name.rfind("sensor_", 0) == 0 && shown < 7)
            add_series(panel, stats, name, name.substr(7), plot::palette(shown++), 1e-3);
    if (!panel.series.empty()) panels.push_back(panel);
}

std::vector<plot::Panel> make_panels(const StatsTable& stats) {
    const std::string empty = stats.rows() == 0 ? "no steps" : "no data";
    std::vector<plot::Panel> panels;
    panels.push_back(make_panel("step size dt (ms)", empty));
    add_series(panels.back(), stats, "dt", "", plot::palette(0), 1e3);
    panels.push_back(make_panel("PCISPH iterations per step", empty));
    add_series(panels.back(), stats, "iterations", "", plot::palette(0));
    panels.push_back(make_panel("density error (%)", empty));
    add_series(panels.back(), stats, "density_error_max", "maximum", plot::palette(1), 100);
    add_series(panels.back(), stats, "density_error_avg", "average", plot::palette(0), 100);
    const bool solids = stats.column("solid_max_speed") || stats.column("solid_kinetic_energy");
    panels.push_back(make_panel("largest speed (m/s)", empty));
    add_series(panels.back(), stats, "max_speed", solids ? "fluid" : "", plot::palette(0));
    add_series(panels.back(), stats, "solid_max_speed", "solids", plot::palette(1));
    panels.push_back(make_panel("kinetic energy (J)", empty));
    add_series(panels.back(), stats, "kinetic_energy", solids ? "fluid" : "", plot::palette(0));
    add_series(panels.back(), stats, "solid_kinetic_energy", "solids", plot::palette(1));
    panels.push_back(stage_panel(stats, empty));
    if (stats.column("heat_content")) {
        panels.push_back(make_panel("heat content (J)", empty));
        add_series(panels.back(), stats, "heat_content", "", plot::palette(1));
    }
    add_sensor_panel(panels, stats, empty);
    add_count_panel(panels, stats, empty);
    return panels;
}

// The steps whose `column` is non-zero, at their simulated time.
plot::MarkSet steps_where(const StatsTable& stats, const std::string& column, const std::string& name, Rgb colour) {
    plot::MarkSet marks{name, {}, colour};
    const std::vector<double>* values = stats.column(column);
    if (!values) return marks;
    for (std::size_t row = 0; row < stats.rows(); ++row)
        if ((*values)[row] != 0) marks.x.push_back((*stats.column("time"))[row]);
    return marks;
}

// The run directory's own name, also for "results/run/" and ".".
std::string run_name(const std::string& run_dir) {
    fs::path path = fs::absolute(fs::path(run_dir)).lexically_normal();
    if (!path.has_filename()) path = path.parent_path();
    return path.filename().string();
}

// The title line: run, scene, steps and time, status; the subtitle: the error of a failed run,
// else the backend and speed.
void add_titles(plot::Figure& figure, const std::string& run_dir, const StatsTable& stats,
                const nlohmann::json& summary, const std::string& summary_note) {
    const std::size_t rows = stats.rows();
    const std::string scene = json_text(summary, "scene_name");
    std::string title = run_name(run_dir) + (scene.empty() || scene == run_name(run_dir) ? "" : " (" + scene + ")");
    if (rows == 0) {
        title += ": no steps";
    } else {
        // The last step's number: a resumed run's stats.csv holds the steps before the resume too.
        const double last_step = stats.column("step")->back(), last_time = stats.column("time")->back();
        const long steps = std::isfinite(last_step) && std::fabs(last_step) < 1e15 ? long(last_step) : long(rows);
        char time[32];
        std::snprintf(time, sizeof time, "%.4g", last_time);
        title += ": " + count_of(steps, "step") + " to t = " + time + " s";
    }
    const std::string status = json_text(summary, "status");
    title += ", " + (status.empty() ? summary_note : status);
    figure.title = title;
    if (status == "failed" || status == "interrupted") {
        const std::string error = json_text(summary, "error");
        figure.subtitle = status + (error.empty() ? "" : ": " + error);
        figure.subtitle_colour = status == "failed" ? Rgb{190, 30, 30} : Rgb{170, 100, 0};
        return;
    }
    std::vector<std::string> details;
    const std::string backend = json_text(summary, "backend"), device = json_text(summary, "device");
    if (!backend.empty()) details.push_back(backend + (device.empty() ? "" : " (" + device + ")"));
    if (summary.contains("particles") && summary["particles"].is_object())
        if (const double total = json_number(summary["particles"], "total"); std::isfinite(total))
            details.push_back(with_thousands(long(total)) + " particles");
    if (const double wall = json_number(summary, "wall_seconds"); std::isfinite(wall))
        details.push_back(format_number(std::round(wall * 10) / 10) + " s wall");
    if (summary.contains("ms_per_step") && summary["ms_per_step"].is_object())
        if (const double ms = json_number(summary["ms_per_step"], "total"); std::isfinite(ms))
            details.push_back(format_number(std::round(ms * 10) / 10) + " ms/step median");
    for (std::size_t k = 0; k < details.size(); ++k) figure.subtitle += (k ? ", " : "") + details[k];
}

plot::Figure make_figure(const std::string& run_dir, const StatsTable& stats, const nlohmann::json& summary,
                         const std::string& summary_note) {
    plot::Figure figure;
    add_titles(figure, run_dir, stats, summary, summary_note);
    figure.x_label = "simulated time (s)";
    figure.panels = make_panels(stats);
    for (plot::MarkSet marks : {steps_where(stats, "dt_retries", "retried steps", {240, 160, 40}),
                                steps_where(stats, "unconverged", "unconverged", {170, 90, 200}),
                                steps_where(stats, "diverged", "diverged", {220, 40, 40})})
        if (!marks.x.empty()) figure.marks.push_back(marks);
    return figure;
}

// --width and --height: whole pixels in [low, 8000].
int size_option(const cxxopts::ParseResult& args, const std::string& name, long fallback, long low) {
    const long value = integer_option(args, name, fallback);
    if (value < low || value > 8000)
        throw InputError("--" + name + " must be in [" + std::to_string(low) + ", 8000] pixels, got " +
                         std::to_string(value));
    return int(value);
}

}  // namespace

int command_plot(int argc, char** argv) {
    cxxopts::Options options("meltwater plot",
                             "Draws RUN_DIR/stats.csv (a run finished, running or failed) as one PNG: step size,\n"
                             "PCISPH iterations, density error, speeds, kinetic energy and stage times against\n"
                             "simulated time, titled with summary.json's status; retried and diverged steps marked.");
    options.add_options()
        ("run_dir", "the run's output directory", cxxopts::value<std::string>())
        ("out", "the PNG to write (default RUN_DIR/plot.png)", cxxopts::value<std::string>(), "FILE")
        ("width", "picture width in pixels, 640 to 8000 (default 1500)", cxxopts::value<std::string>(), "W")
        ("height", "picture height in pixels, 480 to 8000 (default 1000)", cxxopts::value<std::string>(), "H")
        ("h,help", "show this help");
    options.parse_positional({"run_dir"});
    options.positional_help("RUN_DIR");
    const cxxopts::ParseResult args = parse_options(options, argc, argv);
    if (flag_option(args, "help")) {
        std::printf("%s\n", options.help().c_str());
        return 0;
    }
    if (!args.count("run_dir")) throw InputError("plot: missing RUN_DIR (a directory that 'meltwater run' wrote)");
    const int width = size_option(args, "width", 1500, 640), height = size_option(args, "height", 1000, 480);
    const std::string run_dir = args["run_dir"].as<std::string>();
    std::error_code error;
    if (!fs::is_directory(run_dir, error))
        throw InputError(run_dir + ": " + (fs::exists(run_dir, error) ? "not a directory" : "no such directory"));
    const std::string stats_path = (fs::path(run_dir) / "stats.csv").string();
    if (!fs::exists(stats_path, error)) throw InputError(run_dir + " has no stats.csv (is it a run's directory?)");
    const std::string out = args.count("out") ? args["out"].as<std::string>() : (fs::path(run_dir) / "plot.png").string();
    if (out.empty()) throw InputError("--out: empty file name");
    if (fs::is_directory(out, error)) throw InputError("--out: " + out + " is a directory (name the PNG file)");

    const StatsTable stats = read_stats(stats_path);
    std::string summary_note;
    const nlohmann::json summary = read_summary((fs::path(run_dir) / "summary.json").string(), &summary_note);
    const Image image = plot::draw_figure(make_figure(run_dir, stats, summary, summary_note), width, height);
    const std::string png = encode_png(image);
    write_file_atomically(out, [&](std::ostream& stream) { stream.write(png.data(), std::streamsize(png.size())); });
    std::printf("meltwater: plot of %s in %s\n", count_of(long(stats.rows()), "step").c_str(), out.c_str());
    return 0;
}

}  // namespace mw
