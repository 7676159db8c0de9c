#include "render/plot.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace mw::plot {

namespace {

// Values beyond this are drawn at it: the width of a range of two such values is still a finite
// double, where one of two near DBL_MAX would overflow to inf.
constexpr double kLargest = 1e300;
// The height of a capital letter of stb_easy_font in font pixels (its line is 12).
constexpr int kCapHeight = 7;

double clamp_huge(double v) { return std::clamp(v, -kLargest, kLargest); }

// The digits after the decimal point that multiples of `step` need: 0.25 -> 2, 5 -> 0.
int decimals_for(double step) {
    int decimals = std::max(0, int(-std::floor(std::log10(step) + 1e-9)));
    // 2.5 x 10^k needs one more digit than 10^k; the check covers any other step too.
    while (decimals < 15) {
        const double scaled = step * std::pow(10.0, decimals);
        if (std::fabs(scaled - std::round(scaled)) < 1e-6 * std::max(1.0, scaled)) break;
        ++decimals;
    }
    return decimals;
}

}  // namespace

Ticks nice_ticks(double lo, double hi, int most) {
    most = std::max(most, 2);
    if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0, hi = 1;
    if (lo > hi) std::swap(lo, hi);
    lo = clamp_huge(lo), hi = clamp_huge(hi);
    if (hi - lo <= 1e-9 * std::max(std::fabs(lo), std::fabs(hi)) || hi == lo) {
        // One value (or a range too narrow for distinct labels): 10 percent around it (1 around
        // 0), so the value sits in the middle.
        const double half = lo == 0 ? 1.0 : std::max(std::fabs(lo) * 0.1, 1e-300);
        lo -= half, hi += half;
    }
    const double raw_step = (hi - lo) / (most - 1);
    const double decade = std::pow(10.0, std::floor(std::log10(raw_step)));
    static constexpr std::array<double, 5> kMultiples{1, 2, 2.5, 5, 10};
    // The loose bounds (out to whole steps) can add a tick at each end, so a step a few sizes up
    // from raw_step may be needed. A range across 0 needs 3 ticks at least (-s, 0, s); the
    // fewest found is kept for that case.
    Ticks fewest;
    fewest.count = 0;
    for (double scale = decade; scale <= decade * 1000; scale *= 10) {
        for (const double multiple : kMultiples) {
            Ticks ticks;
            ticks.step = multiple * scale;
            // A bound a millionth of a step past a tick (a float time such as 0.600000024) ends
            // there, not a whole step further.
            ticks.first = std::floor(lo / ticks.step + 1e-6) * ticks.step;
            const double last = std::ceil(hi / ticks.step - 1e-6) * ticks.step;
            ticks.count = std::max(int(std::lround((last - ticks.first) / ticks.step)) + 1, 2);
            if (ticks.count <= most) return ticks;
            if (fewest.count == 0 || ticks.count < fewest.count) fewest = ticks;
        }
    }
    return fewest;
}

std::string tick_label(double value, double step) {
    if (!std::isfinite(value)) return "?";
    step = std::fabs(step);
    if (!(step > 0) || !std::isfinite(step)) step = value != 0 ? std::fabs(value) : 1.0;
    // A multiple of the step that rounding left a hair off zero is zero (never "-0" or "1e-17").
    if (std::fabs(value) < step * 1e-6) return "0";
    char text[48];
    const double magnitude = std::fabs(value);
    if (magnitude < 1e6 && step >= 1e-4) {
        std::snprintf(text, sizeof text, "%.*f", decimals_for(step), value);
        return text;
    }
    // Scientific, with the mantissa's digits the step needs: 1.5e-5, 2e7.
    int exponent = int(std::floor(std::log10(magnitude)));
    for (int attempt = 0; attempt < 2; ++attempt) {
        const double unit = std::pow(10.0, exponent);
        const int decimals = decimals_for(step / unit);
        std::snprintf(text, sizeof text, "%.*f", decimals, value / unit);
        // Rounding can carry the mantissa to 10 (9.9996e6 shown as 10.0e6): one exponent up.
        if (std::fabs(std::atof(text)) < 10) break;
        ++exponent;
    }
    return std::string(text) + "e" + std::to_string(exponent);
}

Rgb palette(int index) {
    static constexpr std::array<Rgb, 7> kColours{{{0, 114, 178},    // blue
                                                  {213, 94, 0},     // vermillion
                                                  {0, 158, 115},    // bluish green
                                                  {204, 121, 167},  // reddish purple
                                                  {230, 159, 0},    // orange
                                                  {86, 180, 233},   // sky blue
                                                  {100, 100, 100}}};  // grey
    const int n = int(kColours.size());
    return kColours[std::size_t(((index % n) + n) % n)];
}

namespace {

constexpr Rgb kBackground{255, 255, 255};
constexpr Rgb kGrid{232, 232, 232};
constexpr Rgb kAxis{120, 120, 120};
constexpr Rgb kLabel{70, 70, 70};
constexpr Rgb kTitle{25, 25, 25};

struct Rect {
    int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1)
    int width() const { return x1 - x0; }
    int height() const { return y1 - y0; }
};

// One axis: where its values go on the picture. A log axis works in log10 of the values: its
// ends and ticks are decades.
struct Axis {
    bool log = false;
    double lo = 0, hi = 1;  // its ends; a linear axis's are its first and last ticks
    Ticks ticks;            // within [lo, hi]
    static Axis linear(const Ticks& ticks) {
        Axis axis;
        axis.ticks = ticks;
        axis.lo = ticks.first, axis.hi = ticks.last();
        return axis;
    }
    // The position of `v` along the axis, 0 at its start and 1 at its end; NaN where it has no
    // place (non-finite, or <= 0 on a log axis).
    double fraction(double v) const {
        if (!std::isfinite(v) || (log && v <= 0)) return NAN;
        const double u = log ? std::log10(v) : clamp_huge(v);
        return (u - lo) / (hi - lo);
    }
    double tick_fraction(int i) const { return (ticks.at(i) - lo) / (hi - lo); }
    // The value at tick i, in the values' own units.
    double tick_value(int i) const { return log ? std::pow(10.0, ticks.at(i)) : ticks.at(i); }
    std::string label(int i) const {
        const double v = tick_value(i);
        return tick_label(v, log ? v : ticks.step);
    }
};

// Every finite point of the panel's series (positive ones only when `positive`).
std::vector<double> finite_values(const Panel& panel, bool positive) {
    std::vector<double> values;
    for (const Series& s : panel.series)
        for (std::size_t i = 0; i < s.y.size() && i < s.x.size(); ++i)
            if (std::isfinite(s.x[i]) && std::isfinite(s.y[i]) && (!positive || s.y[i] > 0)) values.push_back(s.y[i]);
    return values;
}

// Whether one series, alone, would be squashed on a linear axis: all its values positive, over
// more than three decades, most of them in the bottom 2 percent of its range (a run that blows up
// at its end). A series that is merely small beside another (a cheap stage) does not count.
bool squashed(const Series& series) {
    std::vector<double> values;
    for (std::size_t i = 0; i < series.x.size() && i < series.y.size(); ++i)
        if (std::isfinite(series.x[i]) && std::isfinite(series.y[i])) values.push_back(series.y[i]);
    if (values.size() < 3) return false;
    const auto [low, high] = std::minmax_element(values.begin(), values.end());
    if (!(*low > 0) || *high < 1e3 * *low) return false;
    const double top = *high;
    std::nth_element(values.begin(), values.begin() + std::ptrdiff_t(values.size() / 2), values.end());
    return values[values.size() / 2] < 0.02 * top;
}

bool wants_log(const Panel& panel) {
    if (panel.scale != YScale::kAuto) return panel.scale == YScale::kLog;
    return std::any_of(panel.series.begin(), panel.series.end(), squashed);
}

// A log axis from the decade at or below the smallest value to the one at or above the
// largest, with a tick every 1, 2, 3 or 5 decades (times a power of ten), at most `most` of them
// (at least one). Its ends need not be ticks: a range of 30 decades is not stretched to 40.
Axis log_axis(double low, double high, int most) {
    Axis axis;
    axis.log = true;
    axis.lo = std::floor(std::log10(low));
    axis.hi = std::max(std::ceil(std::log10(high)), axis.lo + 1);
    for (double scale = 1; scale <= 1000; scale *= 10)
        for (const double multiple : {1.0, 2.0, 3.0, 5.0}) {
            const double step = multiple * scale;
            const double first = std::ceil(axis.lo / step) * step, last = std::floor(axis.hi / step) * step;
            axis.ticks.first = first, axis.ticks.step = step;
            axis.ticks.count = std::max(1, int(std::lround((last - first) / step)) + 1);
            if (axis.ticks.count <= most) return axis;
        }
    return axis;  // a step of 5000 decades: more than doubles hold, so one tick
}

Axis y_axis_for(const Panel& panel, int most_ticks) {
    const bool log = wants_log(panel);
    const std::vector<double> values = finite_values(panel, log);
    if (values.empty()) return Axis::linear(nice_ticks(0, 1, most_ticks));
    const auto [low, high] = std::minmax_element(values.begin(), values.end());
    if (log) return log_axis(*low, *high, most_ticks);
    double lo = clamp_huge(*low), hi = clamp_huge(*high);
    if (panel.include_zero) lo = std::min(lo, 0.0), hi = std::max(hi, 0.0);
    // A little room beyond the extremes, so a curve at a round value (3 iterations every step)
    // runs inside the frame rather than along it; none beyond a zero the axis was asked to reach.
    const double room = 0.03 * (hi - lo);
    if (!(panel.include_zero && lo == 0)) lo -= room;
    if (!(panel.include_zero && hi == 0)) hi += room;
    if (lo == 0 && hi == 0) hi = 1;  // all zero: the value on the axis's floor, not in the middle
    return Axis::linear(nice_ticks(lo, hi, most_ticks));
}

// The x range of every finite point in every panel.
Axis x_axis_for(const Figure& figure, int most_ticks) {
    double lo = INFINITY, hi = -INFINITY;
    for (const Panel& panel : figure.panels)
        for (const Series& s : panel.series)
            for (std::size_t i = 0; i < s.x.size() && i < s.y.size(); ++i)
                if (std::isfinite(s.x[i]) && std::isfinite(s.y[i])) lo = std::min(lo, s.x[i]), hi = std::max(hi, s.x[i]);
    // A single positive x (one step): an axis from 0 to it, rather than 10 percent around it.
    if (lo == hi && lo > 0) lo = 0;
    return Axis::linear(lo <= hi ? nice_ticks(lo, hi, most_ticks) : nice_ticks(0, 1, most_ticks));
}

// `text` cut to at most `width` pixels, ending in "..." when cut.
std::string fit_text(const std::string& text, int width, int scale) {
    if (text_width(text, scale) <= width) return text;
    std::string cut = text;
    while (!cut.empty() && text_width(cut + "...", scale) > width) cut.pop_back();
    return cut.empty() ? "" : cut + "...";
}

// Text whose strokes are one pixel wider: the panels' titles stand out from their tick labels.
void draw_bold_text(Image& image, int x, int y, const std::string& text, Rgb colour, int scale) {
    draw_text(image, x, y, text, colour, scale);
    if (scale > 1) draw_text(image, x + 1, y, text, colour, scale);
}

// The legend's entries (named series) flowed into lines no wider than `width`: a swatch and the
// name, names cut to fit.
struct LegendEntry {
    const Series* series;
    std::string text;
    int width;
};
std::vector<std::vector<LegendEntry>> legend_lines(const Panel& panel, int width, int scale) {
    const int swatch = 12 * scale, gap = 3 * scale, spacing = 10 * scale;
    std::vector<std::vector<LegendEntry>> lines;
    int used = 0;
    for (const Series& s : panel.series) {
        if (s.name.empty()) continue;
        const std::string text = fit_text(s.name, std::max(0, width - swatch - gap), scale);
        const int entry_width = swatch + gap + text_width(text, scale);
        if (lines.empty() || used + spacing + entry_width > width) {
            lines.emplace_back();
            used = -spacing;
        }
        lines.back().push_back({&s, text, entry_width});
        used += spacing + entry_width;
    }
    return lines;
}

// What every panel shares: the text scale, the x axis and the space around each plot.
struct Layout {
    int scale = 1;
    int columns = 1, rows = 1;
    Axis x;
    Rect header;  // the title and subtitle lines
    Rect grid;    // the panels' cells
    int gap = 0;  // between a label and what it labels
    int title_top = 0;  // from a cell's top to its title: keeps it clear of the tick labels above
    int title_band = 0, tick_band = 0, right_pad = 0;
    int cell_width = 0, cell_height = 0;
    std::vector<int> legend_band;  // per row: the most legend lines of its panels, in pixels
    std::vector<int> left_margin;  // per column: the widest y tick label and a gap
    std::vector<Axis> y;           // per panel
    // Panel p's share of the grid.
    Rect cell(int p) const {
        const int x0 = grid.x0 + (p % columns) * cell_width, y0 = grid.y0 + (p / columns) * cell_height;
        return {x0, y0, x0 + cell_width, y0 + cell_height};
    }
    int legend_width() const { return cell_width - 4 * scale; }
};

int auto_scale(int width, int height) {
    const double fit = std::min(width / 760.0, height / 520.0);
    return std::clamp(int(std::lround(fit)), 1, 4);
}

// The column count whose cells come closest to 9:5: wide panels, as suits curves over time.
int auto_columns(int panels, int width, int height) {
    int best = 1;
    double best_miss = INFINITY;
    for (int columns = 1; columns <= std::max(panels, 1); ++columns) {
        const int rows = (panels + columns - 1) / columns;
        const double aspect = (double(width) / columns) / (double(std::max(height, 1)) / std::max(rows, 1));
        const double miss = std::fabs(std::log(aspect / 1.8));
        if (miss < best_miss - 1e-9) best = columns, best_miss = miss;
    }
    return best;
}

// The most x ticks whose labels fit side by side under a plot `width` pixels wide, a label's
// width apart at least.
Axis fitted_x_axis(const Figure& figure, int width, int scale) {
    for (int most = std::max(2, width / (12 * scale)); most > 2; --most) {
        const Axis axis = x_axis_for(figure, most);
        int widest = 0;
        for (int i = 0; i < axis.ticks.count; ++i) widest = std::max(widest, text_width(axis.label(i), scale));
        const double spacing = double(width) / std::max(axis.ticks.count - 1, 1);
        if (spacing >= widest + 4 * 6 * scale) return axis;
    }
    return x_axis_for(figure, 2);
}

Layout plan(const Figure& figure, int width, int height) {
    Layout l;
    l.scale = figure.text_scale > 0 ? figure.text_scale : auto_scale(width, height);
    const int s = l.scale, line = text_height(s), panels = int(figure.panels.size());
    l.gap = 4 * s;
    l.columns = figure.columns > 0 ? figure.columns : auto_columns(panels, width, height);
    l.rows = std::max(1, (panels + l.columns - 1) / l.columns);
    const int outer = 6 * s;
    const int title_lines = 1 + (!figure.subtitle.empty() || !figure.marks.empty());
    l.header = {outer, outer, width - outer, outer + text_height(s + 1) + (title_lines - 1) * (line + s)};
    const int x_label_band = figure.x_label.empty() ? 0 : line;
    l.grid = {outer, l.header.y1 + 2 * s, width - outer, height - outer - x_label_band};
    l.title_top = 3 * l.gap;
    l.title_band = l.title_top + line + l.gap;
    l.tick_band = l.gap + line;
    l.cell_width = l.grid.width() / l.columns;
    l.cell_height = l.grid.height() / l.rows;
    l.legend_band.assign(std::size_t(l.rows), 0);
    for (int p = 0; p < panels; ++p) {
        const int lines = int(legend_lines(figure.panels[std::size_t(p)], l.legend_width(), s).size());
        l.legend_band[std::size_t(p / l.columns)] = std::max(l.legend_band[std::size_t(p / l.columns)], lines * line);
    }
    l.left_margin.assign(std::size_t(l.columns), 0);
    for (int p = 0; p < panels; ++p) {
        const int plot_height =
            l.cell_height - l.title_band - l.legend_band[std::size_t(p / l.columns)] - l.tick_band - 2 * l.gap;
        const int most_y = std::clamp(plot_height * 2 / (line * 3), 2, 9);
        l.y.push_back(y_axis_for(figure.panels[std::size_t(p)], most_y));
        int& margin = l.left_margin[std::size_t(p % l.columns)];
        for (int i = 0; i < l.y.back().ticks.count; ++i)
            margin = std::max(margin, text_width(l.y.back().label(i), s) + 2 * l.gap);
    }
    // The widest left margin decides the x ticks: the narrowest plot must hold their labels.
    const int widest_margin = *std::max_element(l.left_margin.begin(), l.left_margin.end());
    l.right_pad = 10 * s;
    l.x = fitted_x_axis(figure, l.cell_width - widest_margin - l.right_pad, s);
    // The last x label is centred on the plot's right edge: room for its right half.
    l.right_pad = std::max(l.right_pad, text_width(l.x.label(l.x.ticks.count - 1), s) / 2 + 2 * s);
    return l;
}

// The plot area of panel p (inside its axes).
Rect plot_rect(const Layout& l, int p) {
    const Rect cell = l.cell(p);
    Rect r;
    r.x0 = cell.x0 + l.left_margin[std::size_t(p % l.columns)];
    r.x1 = cell.x1 - l.right_pad;
    r.y0 = cell.y0 + l.title_band + l.legend_band[std::size_t(p / l.columns)] + l.gap;
    r.y1 = cell.y1 - l.tick_band - l.gap;
    return r;
}

int to_px_x(const Rect& r, const Axis& x, double v) { return r.x0 + int(std::lround(x.fraction(v) * (r.width() - 1))); }
int to_px_y(const Rect& r, const Axis& y, double v) { return r.y1 - 1 - int(std::lround(y.fraction(v) * (r.height() - 1))); }

void draw_axes(Image& image, const Layout& l, const Rect& r, const Axis& y) {
    const int s = l.scale, tick = 2 * s, cap = kCapHeight * s;
    // Grid lines at the ticks inside the frame (not over its edges).
    for (int i = 0; i < y.ticks.count; ++i) {
        const int py = r.y1 - 1 - int(std::lround(y.tick_fraction(i) * (r.height() - 1)));
        if (py > r.y0 && py < r.y1 - 1) draw_line(image, r.x0, py, r.x1 - 1, py, kGrid);
        draw_line(image, r.x0 - tick, py, r.x0 - 1, py, kAxis);
        const std::string label = y.label(i);
        draw_text(image, r.x0 - tick - l.gap / 2 - text_width(label, s), py - cap / 2, label, kLabel, s);
    }
    for (int i = 0; i < l.x.ticks.count; ++i) {
        const int px = r.x0 + int(std::lround(l.x.tick_fraction(i) * (r.width() - 1)));
        if (px > r.x0 && px < r.x1 - 1) draw_line(image, px, r.y0, px, r.y1 - 1, kGrid);
        draw_line(image, px, r.y1, px, r.y1 + tick - 1, kAxis);
        const std::string label = l.x.label(i);
        draw_text(image, px - text_width(label, s) / 2, r.y1 + tick + l.gap / 2, label, kLabel, s);
    }
    // The frame last, over the grid lines' ends.
    draw_line(image, r.x0, r.y0, r.x1 - 1, r.y0, kGrid);
    draw_line(image, r.x1 - 1, r.y0, r.x1 - 1, r.y1 - 1, kGrid);
    draw_line(image, r.x0, r.y0, r.x0, r.y1 - 1, kAxis);
    draw_line(image, r.x0, r.y1 - 1, r.x1 - 1, r.y1 - 1, kAxis);
}

void draw_marks(Image& image, const Figure& figure, const Rect& r, const Axis& x, int scale) {
    for (const MarkSet& set : figure.marks) {
        // Each pixel column once: thousands of marked steps blend no darker than one.
        std::vector<bool> marked(std::size_t(std::max(r.width(), 0)), false);
        for (const double v : set.x) {
            const double f = x.fraction(v);
            if (!(f >= 0 && f <= 1)) continue;
            for (int dx = 0; dx < scale; ++dx) {
                const int column = to_px_x(r, x, v) - r.x0 + dx;
                if (column >= 0 && column < r.width()) marked[std::size_t(column)] = true;
            }
        }
        for (int column = 0; column < r.width(); ++column)
            if (marked[std::size_t(column)])
                for (int py = r.y0 + 1; py < r.y1 - 1; ++py) image.blend(r.x0 + column, py, set.colour, 0.5f);
    }
}

// A series as a polyline broken at every point that has no place on the axes; a point with no
// drawable neighbour is a small square, so a lone value (one step) still shows.
void draw_series(Image& image, const Series& s, const Rect& r, const Axis& x, const Axis& y, int thickness) {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    const auto drawable = [&](std::size_t i) {
        return i < n && std::isfinite(x.fraction(s.x[i])) && std::isfinite(y.fraction(s.y[i]));
    };
    for (std::size_t i = 0; i < n; ++i) {
        if (!drawable(i)) continue;
        const int px = to_px_x(r, x, s.x[i]), py = to_px_y(r, y, s.y[i]);
        if (drawable(i + 1)) {
            draw_line(image, px, py, to_px_x(r, x, s.x[i + 1]), to_px_y(r, y, s.y[i + 1]), s.colour, thickness);
        } else if (i == 0 || !drawable(i - 1)) {
            const int half = thickness + 1;
            fill_rect(image, px - half, py - half, px + half + 1, py + half + 1, s.colour);
        }
    }
}

// Between the panel's title and its plot, so that it never hides a curve: each line centred
// over the plot, kept inside [left, right).
void draw_legend(Image& image, const std::vector<std::vector<LegendEntry>>& lines, int centre, int left, int right,
                 int top, int scale) {
    const int swatch = 12 * scale, gap = 3 * scale, spacing = 10 * scale, line = text_height(scale);
    for (std::size_t k = 0; k < lines.size(); ++k) {
        int width = -spacing;
        for (const LegendEntry& e : lines[k]) width += spacing + e.width;
        int x = std::clamp(centre - width / 2, left, std::max(left, right - width));
        const int y = top + int(k) * line, mid = y + kCapHeight * scale / 2;
        for (const LegendEntry& e : lines[k]) {
            draw_line(image, x, mid, x + swatch - 1, mid, e.series->colour, 2 * scale);
            draw_text(image, x + swatch + gap, y, e.text, kLabel, scale);
            x += e.width + spacing;
        }
    }
}

void draw_panel(Image& image, const Figure& figure, const Layout& l, int p) {
    const Panel& panel = figure.panels[std::size_t(p)];
    const Rect r = plot_rect(l, p), cell = l.cell(p);
    if (r.width() < 8 || r.height() < 8) return;
    const Axis& y = l.y[std::size_t(p)];
    const int s = l.scale, title_y = cell.y0 + l.title_top;
    const std::string title = fit_text(panel.title, cell.width() - 4 * s, s);
    const int title_x = std::clamp((r.x0 + r.x1 - text_width(title, s)) / 2, cell.x0, cell.x1 - text_width(title, s));
    draw_bold_text(image, title_x, title_y, title, kTitle, s);
    draw_axes(image, l, r, y);
    draw_marks(image, figure, r, l.x, s);
    bool any = false;
    for (const Series& series : panel.series) {
        draw_series(image, series, r, l.x, y, series.thickness > 0 ? series.thickness : std::max(1, s));
        for (std::size_t i = 0; i < series.x.size() && i < series.y.size() && !any; ++i)
            any = std::isfinite(l.x.fraction(series.x[i])) && std::isfinite(y.fraction(series.y[i]));
    }
    if (!any) {
        const std::string note = fit_text(panel.empty_text, r.width() - 4 * s, s + 1);
        draw_text(image, (r.x0 + r.x1 - text_width(note, s + 1)) / 2, (r.y0 + r.y1 - kCapHeight * (s + 1)) / 2, note,
                  kAxis, s + 1);
        return;
    }
    draw_legend(image, legend_lines(panel, l.legend_width(), s), (r.x0 + r.x1) / 2, cell.x0 + 2 * s,
                cell.x1 - 2 * s, cell.y0 + l.title_band, s);
}

// 60098 as "60,098".
std::string grouped(long n) {
    std::string digits = std::to_string(n), out;
    for (std::size_t i = 0; i < digits.size(); ++i) {
        if (i > 0 && (digits.size() - i) % 3 == 0 && digits[i - 1] != '-') out += ',';
        out += digits[i];
    }
    return out;
}

// The title, the subtitle under it, and the marks' legend ("| retried (3)") at the subtitle's right.
void draw_header(Image& image, const Figure& figure, const Layout& l) {
    const int s = l.scale, big = s + 1;
    const Rect& h = l.header;
    draw_bold_text(image, h.x0, h.y0, fit_text(figure.title, h.width(), big), kTitle, big);
    const int y = h.y0 + text_height(big) + s;
    int right = h.x1;
    for (auto set = figure.marks.rbegin(); set != figure.marks.rend(); ++set) {
        const std::string text = set->name + " (" + grouped(long(set->x.size())) + ")";
        const int w = text_width(text, s);
        if (right - w - 8 * s < h.x0) break;
        draw_text(image, right - w, y, text, kLabel, s);
        fill_rect(image, right - w - 6 * s, y - s, right - w - 3 * s, y + (kCapHeight + 1) * s, set->colour);
        right -= w + 14 * s;
    }
    draw_text(image, h.x0, y, fit_text(figure.subtitle, right - h.x0 - 4 * s, s), figure.subtitle_colour, s);
}

}  // namespace

Image draw_figure(const Figure& figure, int width, int height) {
    Image image(width, height, kBackground);
    const Layout l = plan(figure, width, height);
    draw_header(image, figure, l);
    for (int p = 0; p < int(figure.panels.size()); ++p) draw_panel(image, figure, l, p);
    if (!figure.x_label.empty()) {
        const std::string label = fit_text(figure.x_label, l.grid.width(), l.scale);
        draw_text(image, (l.grid.x0 + l.grid.x1 - text_width(label, l.scale)) / 2, l.grid.y1, label, kLabel, l.scale);
    }
    return image;
}

}  // namespace mw::plot
