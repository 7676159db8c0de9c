// Progress of a run on stderr: one updating line on a terminal, a plain line about every 10% of
// the run otherwise, nothing with --quiet.
#pragma once
#include <chrono>
#include <string>

#include "simulation/simulation.hpp"

namespace mw {

class Progress {
   public:
    enum class Mode { kAuto, kQuiet };
    // Either `end_steps` > 0 (run N steps) or `end_time` > 0 (run to simulated time T), from
    // step `start_step` at `start_time` (a resumed run starts where its checkpoint was written).
    Progress(Mode mode, long end_steps, double end_time, long start_step = 0, double start_time = 0);
    void update(const StepReport& report);
    void finish();  // ends the updating line, if any

   private:
    double fraction(const StepReport& r) const;
    std::string line(const StepReport& r, double frac) const;

    bool quiet_, tty_;
    long end_steps_;
    double end_time_;
    long start_step_;
    double start_time_;
    std::chrono::steady_clock::time_point start_, last_draw_;
    int next_decile_ = 1;
    double recent_ms_ = 0;  // smoothed ms/step
    long seen_ = 0;
    bool drawn_ = false;
};

}  // namespace mw
