#include "apps/atomic_file.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "common/errors.hpp"

namespace mw {

namespace {

std::atomic<long> g_synced_files{0};
std::atomic<long long> g_sync_nanoseconds{0};

// fsync of `path` opened with `flags`. A directory that cannot be synced (some file systems answer
// EINVAL) is left as it is: the rename is then as durable as that file system makes it.
void sync_to_disk(const std::string& path, int flags, const std::string& shown) {
    const int fd = ::open(path.c_str(), flags | O_CLOEXEC);
    if (fd < 0) {
        if (flags & O_DIRECTORY) return;
        throw InputError("cannot open " + shown + " to flush it to disk: " + std::strerror(errno));
    }
    const int result = ::fsync(fd);
    const int error = errno;
    ::close(fd);
    if (result != 0 && !((flags & O_DIRECTORY) && (error == EINVAL || error == EROFS)))
        throw InputError("cannot flush " + shown + " to disk: " + std::strerror(error) + " (disk full or failing?)");
}

}  // namespace

void write_file_atomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
    const std::string temporary = path + ".tmp." + std::to_string(::getpid());
    {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) throw InputError("cannot write " + path + " (is the output directory writable?)");
        write(out);
        out.close();
        if (!out) {
            std::remove(temporary.c_str());
            throw InputError("failed while writing " + path + " (disk full?)");
        }
    }
    // On disk before the rename, so that after a power cut the name holds either the whole new
    // content or the whole old one; the directory after it, so that the rename itself persists.
    const auto sync_start = std::chrono::steady_clock::now();
    try {
        sync_to_disk(temporary, O_WRONLY, path);
    } catch (...) {
        std::remove(temporary.c_str());
        throw;
    }
    std::error_code error;
    std::filesystem::rename(temporary, path, error);
    if (error) {
        std::remove(temporary.c_str());
        throw InputError("cannot rename " + temporary + " to " + path + ": " + error.message());
    }
    const std::string directory = std::filesystem::path(path).parent_path().string();
    sync_to_disk(directory.empty() ? "." : directory, O_RDONLY | O_DIRECTORY, "the directory of " + path);
    g_sync_nanoseconds += std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() -
                                                                               sync_start).count();
    ++g_synced_files;
}

DiskSyncTotals disk_sync_totals() { return {g_synced_files.load(), 1e-9 * double(g_sync_nanoseconds.load())}; }

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
