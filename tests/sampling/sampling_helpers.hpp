// Shared bits of the sampling tests: where the real meshes live, a skip helper, the error a call
// throws, and a small OBJ tetrahedron to break in different ways.
#pragma once
#include <filesystem>
#include <functional>
#include <string>

#include <doctest/doctest.h>

#include "common/errors.hpp"
#include "tests/skip.hpp"

namespace mwtest {
inline std::string mesh_dir() { return std::string(MW_SHARED_DIR) + "/assets/meshes"; }
// True (and a MESSAGE saying the test is skipped) when the shared mesh folder or file is absent.
inline bool missing_mesh(const std::string& file) {
    const std::string path = mesh_dir() + "/" + file;
    if (std::filesystem::exists(path)) return false;
    MW_SKIP(path << " is absent (the shared meshes live in ../shared/assets/meshes)");
    return true;
}

// The InputError message `f` throws, or "" when it throws none.
inline std::string error_of(const std::function<void()>& f) {
    try {
        f();
    } catch (const mw::InputError& e) {
        return e.what();
    }
    return "";
}

// The unit tetrahedron as OBJ text, faces wound outward.
inline const std::string kTetVertices = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\n";
inline const std::string kTetFaces = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
}  // namespace mwtest
