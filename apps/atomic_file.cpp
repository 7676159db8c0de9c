#include "apps/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/errors.hpp"

namespace mw {

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
    const std::string temporary = path + ".tmp." + std::to_string(::getpid());
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) throw InputError("cannot write " + path + " (is the output directory writable?)");
        write(out);
        out.flush();
        if (!out) {
            std::remove(temporary.c_str());
            throw InputError("failed while writing " + path + " (disk full?)");
        }
    }
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error) {
        std::remove(temporary.c_str());
        throw InputError("cannot rename " + temporary + " to " + path + ": " + error.message());
    }
}

std::vector<std::string> make_directories(const std::string& path) {
    // What is missing, innermost first: everything from the outermost missing one down is made
    // here. Not normalised: "x/../y" makes x too, and each "p/.." comes before p in the list, so
    // removing it meets p's parent while that still holds p, and leaves it alone.
    std::vector<std::string> created;
    std::error_code error;
    std::filesystem::path full = std::filesystem::absolute(path, error);
    if (!full.has_filename()) full = full.parent_path();  // "out/" names the directory "out"
    for (std::filesystem::path p = full; !error && !p.empty(); p = p.parent_path()) {
        if (std::filesystem::exists(p, error) || error) break;
        created.push_back(p.string());
        if (p == p.parent_path()) break;
    }
    error.clear();
    std::filesystem::create_directories(path, error);
    if (error || !std::filesystem::is_directory(path)) {
        remove_created_directories(created);
        throw InputError("cannot create output directory " + path + (error ? ": " + error.message() : ""));
    }
    // An existing directory may still be read-only: find out now, not after a long run.
    const std::string probe = path + "/.meltwater-write-check." + std::to_string(::getpid());
    {
        std::ofstream out(probe, std::ios::binary | std::ios::trunc);
        if (!out) {
            const std::string reason = std::strerror(errno);
            remove_created_directories(created);
            throw InputError("cannot write in output directory " + path + ": " + reason);
        }
    }
    std::remove(probe.c_str());
    return created;
}

void remove_created_directories(const std::vector<std::string>& created) {
    std::error_code ignored;
    for (const std::string& p : created) std::filesystem::remove(p, ignored);  // only if empty
}

}  // namespace mw
