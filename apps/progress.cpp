#include "apps/progress.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "apps/cli_common.hpp"

namespace mw {

Progress::Progress(Mode mode, long end_steps, double end_time, long start_step, double start_time)
    : quiet_(mode == Mode::kQuiet),
      tty_(::isatty(STDERR_FILENO) != 0),
      end_steps_(end_steps),
      end_time_(end_time),
      start_step_(start_step),
      start_time_(start_time),
      start_(std::chrono::steady_clock::now()),
      last_draw_(start_) {}

double Progress::fraction(const StepReport& r) const {
    const double f = end_steps_ > 0 ? double(r.step - start_step_) / double(end_steps_)
                                    : (r.time - start_time_) / (end_time_ - start_time_);
    return std::clamp(f, 0.0, 1.0);
}

std::string Progress::line(const StepReport& r, double frac) const {
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = frac > 0 ? elapsed * (1 - frac) / frac : -1;
    const double end = end_steps_ > 0 ? (frac > 0 ? start_time_ + (r.time - start_time_) / frac : 0.0) : end_time_;
    const int digits = end >= 0.1 || end == 0 ? 2 : std::min(6, 2 + static_cast<int>(std::ceil(-std::log10(end))));
    char buffer[160];
    std::snprintf(buffer, sizeof buffer, "t=%.*f/%.*f s step %ld | %.1f ms/step | ETA %s", digits, r.time, digits, end,
                  r.step, recent_ms_, format_duration(eta).c_str());
    return buffer;
}

void Progress::update(const StepReport& r) {
    // A running mean over the first 10 steps, then an exponential average of about the last 10.
    ++seen_;
    const double alpha = std::max(0.1, 1.0 / double(seen_));
    recent_ms_ += alpha * (r.total_ms - recent_ms_);
    if (quiet_) return;
    const double frac = fraction(r);
    if (tty_) {
        const auto now = std::chrono::steady_clock::now();
        if (frac < 1 && std::chrono::duration<double>(now - last_draw_).count() < 0.1) return;
        last_draw_ = now;
        const int width = 20, filled = static_cast<int>(frac * width);
        std::string bar(filled, '#');
        bar.append(width - filled, '.');
        std::fprintf(stderr, "\r[%s] %s\033[K", bar.c_str(), line(r, frac).c_str());
        std::fflush(stderr);
        drawn_ = true;
    } else if (frac * 10 >= next_decile_) {
        next_decile_ = static_cast<int>(frac * 10) + 1;
        std::fprintf(stderr, "%3d%% %s\n", static_cast<int>(frac * 100 + 0.5), line(r, frac).c_str());
    }
}

void Progress::finish() {
    if (drawn_) std::fprintf(stderr, "\n");
    drawn_ = false;
}

}  // namespace mw
