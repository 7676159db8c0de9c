// One scratch directory per test process, for the files tests write: under the system's temp
// directory, named by `prefix` and the process id (two suites run at once, say two build
// directories' ctest, keep out of each other's files), and removed when the process exits, so
// that a check that stops a case before its own clean-up leaves nothing behind. Set
// MW_KEEP_TEST_FILES to keep it for a look.
#pragma once
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

namespace mw_test {

inline std::filesystem::path scratch_dir(const std::string& prefix = "meltwater_test") {
    struct Scratch {
        std::filesystem::path path;
        explicit Scratch(const std::string& name)
            : path(std::filesystem::temp_directory_path() / (name + "_" + std::to_string(::getpid()))) {
            std::filesystem::create_directories(path);
        }
        ~Scratch() {
            std::error_code ignored;
            if (!std::getenv("MW_KEEP_TEST_FILES")) std::filesystem::remove_all(path, ignored);
        }
    };
    // The first call names it; a program uses one prefix.
    static const Scratch scratch(prefix);
    return scratch.path;
}

}  // namespace mw_test
