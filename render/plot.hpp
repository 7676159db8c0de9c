// A small line-chart library on render/image.hpp: a figure of panels in a grid, each with its
// axes (round tick values, linear or logarithmic), grid lines, titled, with series drawn as
// lines and a legend, plus vertical marks shared by every panel (events at an x value). It knows
// nothing of what the numbers are; apps/command_plot.cpp draws a run's stats.csv with it.
#pragma once
#include <string>
#include <vector>

#include "render/image.hpp"

namespace mw::plot {

// Tick values for an axis over [lo, hi]: multiples of `step` (1, 2, 2.5 or 5 times a power of
// ten) from `first`, `count` of them, the first at or below lo and the last at or above hi (to a
// millionth of a step), so an axis drawn from the first to the last tick holds the whole range. At most `most` ticks (at
// least 2, and 3 for a range across 0); lo > hi is read as [hi, lo]; lo == hi gives a range
// around the value; a bound that is not finite gives [0, 1]; bounds beyond +-1e300 are cut there.
struct Ticks {
    double first = 0, step = 1;
    int count = 2;
    double at(int i) const { return first + step * i; }
    double last() const { return at(count - 1); }
};
Ticks nice_ticks(double lo, double hi, int most);

// A tick's text with no more digits than `step` needs: "0.25", "40", "-3"; "1.5e-5" and "2e7" for
// values that would need many digits.
std::string tick_label(double value, double step);

struct Series {
    std::string name;          // in the legend; a series with an empty name has no entry
    std::vector<double> x, y;  // the same length; a point with a non-finite x or y breaks the line
    Rgb colour;
    int thickness = 0;  // pixels; 0 picks one from the figure's text scale
};

enum class YScale { kAuto, kLinear, kLog };

struct Panel {
    std::string title;  // units included, e.g. "step size dt (ms)"
    std::vector<Series> series;
    // kAuto: logarithmic when the values are all positive, span more than three decades and most
    // of them would sit in the bottom 2 percent of a linear axis (a run that blows up at its end);
    // else linear. On a log axis a value <= 0 is left out like a non-finite one.
    YScale scale = YScale::kAuto;
    bool include_zero = true;  // a linear axis reaches down (or up) to 0
    // Shown in the middle of the plot when no series has a finite point (e.g. "no steps").
    std::string empty_text = "no data";
};

// Vertical lines at x values in every panel, behind the series (e.g. the steps that were retried).
struct MarkSet {
    std::string name;  // the figure's legend gives it with its count: "retried (3)"
    std::vector<double> x;
    Rgb colour;
};

struct Figure {
    std::string title;     // the first line, in the largest text
    std::string subtitle;  // a second line under it (may be empty)
    Rgb subtitle_colour{90, 90, 90};
    std::string x_label;  // under the bottom row, e.g. "simulated time (s)"
    std::vector<Panel> panels;
    std::vector<MarkSet> marks;
    int columns = 0;     // 0: chosen from the picture's shape and the panel count
    int text_scale = 0;  // each font pixel this many pixels; 0: chosen from the picture's size
};

// Draws the figure at width x height pixels (each 1 to 16384). Every panel shares the x range of
// all the panels' finite points; the marks' legend stands at the right of the subtitle line. The
// text is never cut mid-glyph: a title or legend entry too long for its place ends in "...".
Image draw_figure(const Figure& figure, int width, int height);

// The Okabe-Ito colour-blind-safe palette minus its yellow (too faint on white), then grey:
// a series' colour by its index (wrapping).
Rgb palette(int index);

}  // namespace mw::plot
