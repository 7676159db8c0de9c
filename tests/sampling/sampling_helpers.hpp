// Shared bits of the sampling tests: where the real meshes live, and a skip helper.
#pragma once
#include <filesystem>
#include <string>

#include <doctest/doctest.h>

namespace mwtest {
inline std::string mesh_dir() { return std::string(MW_SHARED_DIR) + "/assets/meshes"; }
// True (and a MESSAGE saying the test is skipped) when the shared mesh folder or file is absent.
inline bool missing_mesh(const std::string& file) {
    const std::string path = mesh_dir() + "/" + file;
    if (std::filesystem::exists(path)) return false;
    MESSAGE("SKIPPED: " << path << " is absent (the shared meshes live in ../shared/assets/meshes)");
    return true;
}
}  // namespace mwtest
