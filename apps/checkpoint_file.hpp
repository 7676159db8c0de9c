// Checkpoint files (`meltwater run --checkpoint`, `--resume`): a simulation's state
// (algorithms/state_archive.hpp) with what a resumed run needs besides: the resolved scene it was
// built from, and the run's frame clock. Layout (docs/checkpoints.md):
//   "MELTWATER CHECKPOINT <version>\n"
//   8 bytes: the header's length in bytes (unsigned, little-endian)
//   header: JSON (the scene, the clock, the frames so far, an index of the blocks)
//   the blocks' bytes, one after another in the index's order
//   8 bytes: FNV-1a 64 of header and blocks (little-endian), so that a truncated or damaged file
//            is refused rather than loaded.
// Written atomically (temporary name, then rename): a run killed mid-write leaves the last whole one.
#pragma once
#include <string>
#include <vector>

#include "algorithms/state_archive.hpp"
#include "apps/scene.hpp"

namespace mw {

struct Checkpoint {
    SceneJson scene;            // the resolved scene (overrides applied, mesh paths absolute)
    std::string backend;        // the backend that wrote it (a resumed run may use the other)
    long step = 0;              // steps taken
    double time = 0;            // simulated time, s
    std::vector<double> frame_times;  // simulated time of each frame written so far (index = NNNNN)
    double next_frame_time = 0;       // when the next frame is due, s
    StateArchive state;
};

constexpr const char* kCheckpointFileName = "checkpoint.mwc";

void write_checkpoint(const std::string& path, const Checkpoint& checkpoint);
// Throws InputError naming the file and the problem (missing, not a checkpoint, another format
// version, truncated, damaged).
Checkpoint read_checkpoint(const std::string& path);
// The same from the file's bytes; `where` names it in messages ("checkpoint 'PATH'").
Checkpoint parse_checkpoint(const std::vector<unsigned char>& file, const std::string& where);

}  // namespace mw
