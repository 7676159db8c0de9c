// A main for the fuzz targets in builds without libFuzzer (gcc, Release): runs the target once on
// each file given, and on each file of each directory given, so that `ctest` replays the seeds and
// every input a fuzzer once failed on (fuzz/regressions/) in every build. A failure is what it
// would be under the fuzzer: a crash, or an exception other than InputError escaping.
#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);

namespace {
int replay(const std::filesystem::path& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) {
        std::fprintf(stderr, "replay: cannot read %s\n", file.c_str());
        return 1;
    }
    const std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
    return 0;
}
}  // namespace

int main(int argc, char** argv) {
    int failures = 0, inputs = 0;
    for (int a = 1; a < argc; ++a) {
        const std::filesystem::path path = argv[a];
        std::error_code error;
        if (!std::filesystem::exists(path, error)) continue;  // an optional folder (the shared meshes)
        std::vector<std::filesystem::path> files;
        if (std::filesystem::is_directory(path, error)) {
            for (const auto& entry : std::filesystem::recursive_directory_iterator(path, error))
                if (entry.is_regular_file()) files.push_back(entry.path());
            std::sort(files.begin(), files.end());
        } else {
            files.push_back(path);
        }
        for (const auto& file : files) {
            failures += replay(file);
            ++inputs;
        }
    }
    std::printf("replay: %d inputs, each read without a crash or an unexpected exception\n", inputs);
    return failures == 0 && inputs > 0 ? 0 : 1;
}
