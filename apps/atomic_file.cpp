#include "apps/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "backend/errors.hpp"

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

void make_directories(const std::string& path) {
    std::error_code error;
    std::filesystem::create_directories(path, error);
    if (error || !std::filesystem::is_directory(path))
        throw InputError("cannot create output directory " + path + (error ? ": " + error.message() : ""));
    // An existing directory may still be read-only: find out now, not after a long run.
    const std::string probe = path + "/.meltwater-write-check." + std::to_string(::getpid());
    {
        std::ofstream out(probe, std::ios::binary | std::ios::trunc);
        if (!out) throw InputError("cannot write in output directory " + path + ": " + std::strerror(errno));
    }
    std::remove(probe.c_str());
}

}  // namespace mw
