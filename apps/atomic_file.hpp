// Writes a file atomically: the content goes to a temporary name beside the target, then one
// rename makes it visible, so a reader (or a crash) never sees a half-written output.
#pragma once
#include <functional>
#include <ostream>
#include <string>

namespace mw {
// Calls write(stream) on a temporary file and renames it to `path`. Throws InputError naming the
// path if the directory cannot be written.
void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write);
// Creates a directory and its parents and checks that a file can be written in it; throws
// InputError naming it on failure.
void make_directories(const std::string& path);
}  // namespace mw
