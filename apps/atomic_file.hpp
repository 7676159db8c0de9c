// Writes a file atomically: the content goes to a temporary name beside the target, then one
// rename makes it visible, so a reader (or a crash) never sees a half-written output.
#pragma once
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace mw {
// Calls write(stream) on a temporary file and renames it to `path`. Throws InputError naming the
// path if the directory cannot be written.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);
// Creates a directory and its parents and checks that a file can be written in it; throws
// InputError naming it on failure (after removing what it created). Returns the directories it
// created, innermost first, so that a command that then fails can leave nothing behind.
std::vector<std::string> make_directories(const std::string& path);
// Removes each of `created` (innermost first) that is empty; the rest, and errors, are left.
void remove_created_directories(const std::vector<std::string>& created);
}  // namespace mw
