// Writes a file atomically and durably: the content goes to a temporary name beside the target,
// is flushed to disk, then one rename makes it visible and the directory is flushed too, so a
// reader, a killed run or a power cut never leaves a half-written output under the target's name.
#pragma once
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace mw {
// Calls write(stream) on a temporary file and renames it to `path`. Throws InputError naming the
// path if the directory cannot be written.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);
// What flushing to disk has cost this process so far: the files written and the seconds spent
// in fsync and rename (summary.json reports them for a run).
struct DiskSyncTotals {
    long files = 0;
    double seconds = 0;
};
DiskSyncTotals disk_sync_totals();
// Creates a directory and its parents and checks that a file can be written in it; throws
// InputError naming it on failure (after removing what it created). Returns the directories it
// created, innermost first, so that a command that then fails can leave nothing behind.
std::vector<std::string> make_directories(const std::string& path);
// Removes each of `created` (innermost first) that is empty; the rest, and errors, are left.
void remove_created_directories(const std::vector<std::string>& created);
}  // namespace mw
