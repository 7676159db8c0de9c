// `meltwater sample` end to end: output files and their fields, and one clear error with a
// non-zero exit for every kind of bad input.
#define DOCTEST_CONFIG_IMPLEMENT
#include <doctest/doctest.h>
#include <unistd.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/sampling/sampling_helpers.hpp"
#include "tests/sanitizer.hpp"
#include "tests/scratch_dir.hpp"
#include "tests/skip.hpp"

namespace {

struct Run {
    int code = -1;
    std::string output;  // stdout and stderr together
};

// `limits` goes before the command in the shell (e.g. a timeout and an address-space limit for
// inputs that once hung or ate memory, so that a regression fails instead of stalling the suite).
Run run_sample(const std::string& args, const std::string& limits = "") {
    const std::string cmd = "export OMP_NUM_THREADS=2; " + limits + " '" + MW_BINARY + "' sample " + args + " 2>&1";
    Run r;
    FILE* p = popen(cmd.c_str(), "r");
    REQUIRE(p != nullptr);
    char buf[4096];
    std::size_t n;
    while ((n = fread(buf, 1, sizeof buf, p)) > 0) r.output.append(buf, n);
    const int status = pclose(p);
    r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

const std::string kGuard = mw_test::memory_and_time_guard();

std::string read_file(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

// This program's scratch directory (tests/scratch_dir.hpp).
std::filesystem::path scratch_dir() { return mw_test::scratch_dir("mw_sample_cli"); }

// An empty directory `name` of the scratch directory, one per test case.
std::filesystem::path temp_dir(const std::string& name) {
    const auto d = scratch_dir() / name;
    std::filesystem::remove_all(d);
    std::filesystem::create_directories(d);
    return d;
}

}  // namespace

TEST_CASE("sample writes SBP, IBP and GP files with type codes and normals, and prints the figures") {
    const auto dir = temp_dir("sphere");
    const Run r = run_sample("sphere:radius=0.5,subdivisions=4 --spacing 0.05 --out '" + (dir / "out").string() + "'");
    INFO(r.output);
    REQUIRE(r.code == 0);
    for (const char* key : {"counts", "SBP", "IBP", "GP", "largest surface gap", "volume", "time"})
        CHECK(r.output.find(key) != std::string::npos);
    const std::string sbp = read_file(dir / "out" / "sbp.vtu");
    const std::string ibp = read_file(dir / "out" / "ibp.vtu");
    const std::string gp = read_file(dir / "out" / "gp.vtu");
    CHECK(sbp.find("Name=\"type\"") != std::string::npos);
    CHECK(sbp.find("Name=\"normal\" NumberOfComponents=\"3\"") != std::string::npos);
    CHECK(ibp.find("Name=\"type\"") != std::string::npos);
    CHECK(gp.find("Name=\"type\"") != std::string::npos);
    // The first appended byte of the type array is the type code (2 SBP, 3 IBP, 4 GP).
    auto first_type = [](const std::string& vtu) {
        const std::size_t at = vtu.find("<AppendedData encoding=\"raw\">");
        REQUIRE(at != std::string::npos);
        const std::size_t data = vtu.find('_', at) + 1 + 8;  // '_' then a UInt64 byte count
        return static_cast<int>(static_cast<unsigned char>(vtu[data]));
    };
    CHECK(first_type(sbp) == 2);
    CHECK(first_type(ibp) == 3);
    CHECK(first_type(gp) == 4);
    std::filesystem::remove_all(dir);
}

TEST_CASE("sample on the real bunny, scaled, transformed") {
    const std::string bunny = std::string(MW_SHARED_DIR) + "/assets/meshes/stanford-bunny.obj";
    if (!std::filesystem::exists(bunny)) {
        MW_SKIP(bunny << " is absent (the shared meshes live in ../shared/assets/meshes)");
        return;
    }
    const auto dir = temp_dir("bunny");
    const Run r = run_sample("'" + bunny + "' --spacing 0.02 --scale 3.2114 --rotate 0,90,0 --translate 1,2,3 --out '" +
                             dir.string() + "'");
    INFO(r.output);
    CHECK(r.code == 0);
    CHECK(r.output.find("open (223 boundary edges)") != std::string::npos);
    std::filesystem::remove_all(dir);
}

TEST_CASE("bad input: one line naming the problem, exit code 2") {
    const auto dir = temp_dir("bad");
    auto write = [&](const std::string& name, const std::string& text) {
        std::ofstream(dir / name) << text;
        return "'" + (dir / name).string() + "'";
    };
    const std::string out = " --out '" + (dir / "out").string() + "'";
    const std::string& tet_vertices = mwtest::kTetVertices;
    const std::string& tet = mwtest::kTetFaces;
    struct Case {
        std::string args, expect;
    };
    const Case cases[] = {
        {"'" + (dir / "missing.obj").string() + "' --spacing 0.1" + out, "missing.obj: mesh file does not exist"},
        {write("none.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n") + " --spacing 0.1" + out, "none.obj: the mesh has no triangles"},
        {write("nan.obj", "v 0 0 0\nv 1 0 0\nv 0 nan 0\nv 0 0 1\n" + tet) + " --spacing 0.1" + out, "nan.obj: vertex 3 is not finite"},
        {write("flat.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n") + " --spacing 0.1" + out,
         "flat.obj: the mesh encloses zero volume"},
        {write("index.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 7\n") + " --spacing 0.1" + out, "index.obj: "},
        {"box --spacing 0" + out, "--spacing must be a positive number"},
        {"box" + out, "missing --spacing"},
        {"box --spacing 0.1", "missing --out"},
        {"--spacing 0.1" + out, "missing MESH"},
        {"sheet --spacing 0.1" + out, "zero volume"},
        {"box:size=3 --spacing 0.1" + out, "unknown parameter 'size'"},
        {"box --spacing 0.1 --scale 1,2" + out, "--scale"},
        {"box --spacing 0.1 --directions 5" + out, "--directions"},
        {"box --spacing 0.1 --bogus" + out, "bogus"},
        // OBJ lines tinyobjloader misreads or drops.
        {write("two.obj", "v 0 0 0\nv 1 0\nv 0 1 0\nv 0 0 1\n" + tet) + " --spacing 0.1" + out,
         "two.obj: vertex 2 has 2 coordinates, a vertex needs x y z (line 2: 'v 1 0')"},
        {write("cut.obj", tet + "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0") + " --spacing 0.1" + out,
         "cut.obj: vertex 4 has 2 coordinates, a vertex needs x y z (line 8: 'v 0 0'); the file ends in this line"},
        {write("edge.obj", tet_vertices + tet + "f 1 3\n") + " --spacing 0.1" + out,
         "edge.obj: face 5 has 2 corners, a face needs at least 3 (line 9: 'f 1 3')"},
        {write("huge.obj", tet_vertices + "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 99999999999\n") +
             " --spacing 0.1" + out,
         "huge.obj: face 4 refers to vertex 99999999999, but the file has 4 vertices (line 8"},
        // Spacings and transforms out of range.
        {"sphere:radius=1 --spacing 1e20" + out, "sphere:radius=1: spacing r0 = 1e+20 is larger than the mesh itself"},
        {"box:x=200000,y=1,z=1 --spacing 1" + out, "too fine for the single-precision ray tracer"},
        {"box --spacing 0.1 --scale 1e300" + out, "box: the transform (scale 1e+300,1e+300,1e+300"},
        {"box --spacing 0.1 --translate 1e30,0,0" + out, "too far for double precision to resolve it"},
        // A mesh with no inner particle is refused, as `meltwater run` refuses it.
        {write("small.obj", tet_vertices + tet) + " --spacing 0.9" + out,
         "small.obj: the mesh holds no inner particle at spacing 0.9 (make it larger or decrease --spacing)"},
        {"box --spacing 0.1 --threads -5" + out, "--threads must be in [1, 1024], got -5"},
        {"box --spacing 0.1 --threads 0" + out, "--threads must be in [1, 1024], got 0"},
        {"box --spacing 0.1 --threads 100000" + out, "--threads must be in [1, 1024], got 100000"},
    };
    for (const Case& c : cases) {
        const Run r = run_sample(c.args, kGuard);
        INFO(c.args << "\n" << r.output);
        CHECK(r.code == 2);
        CHECK(r.output.rfind("meltwater: error: ", 0) == 0);
        CHECK(r.output.find(c.expect) != std::string::npos);
        CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
    }
    CHECK_FALSE(std::filesystem::exists(dir / "out"));
    std::filesystem::remove_all(dir);
}

TEST_CASE("meshes of any size: the ray tracer's float range neither hangs nor exhausts memory") {
    const auto dir = temp_dir("scale");
    std::ofstream(dir / "tet.obj") << mwtest::kTetVertices << mwtest::kTetFaces;
    const struct {
        std::string args, counts;
    } cases[] = {
        {"box:x=1,y=1,z=1 --spacing 1e12 --scale 1e13", "IBP 1000,"},
        {"'" + (dir / "tet.obj").string() + "' --spacing 1e14 --scale 1e15", "IBP 165,"},
        {"box:x=1,y=1,z=1 --spacing 1e-14 --scale 1e-13", "IBP 1000,"},
    };
    for (const auto& c : cases) {
        const Run r = run_sample(c.args + " --no-coverage --out '" + (dir / "out").string() + "'", kGuard);
        INFO(c.args << "\n" << r.output);
        CHECK(r.code == 0);
        CHECK(r.output.find(c.counts) != std::string::npos);
    }
    std::filesystem::remove_all(dir);
}

TEST_CASE("--out is made and checked before sampling, and removed again when sampling fails") {
    const auto dir = temp_dir("out");
    std::ofstream(dir / "file") << "not a directory";
    // Checked first: a spacing refused by the sampler is not what gets reported.
    Run r = run_sample("box --spacing 1e-5 --out '" + (dir / "file" / "out").string() + "'", kGuard);
    INFO(r.output);
    CHECK(r.code == 2);
    CHECK(r.output.find("cannot create output directory") != std::string::npos);
    CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
    // Sampling fails after the directory (and its missing parents) were made: all removed again.
    r = run_sample("box --spacing 1e-5 --out '" + (dir / "new" / "deeper").string() + "'", kGuard);
    INFO(r.output);
    CHECK(r.code == 2);
    CHECK(r.output.find("too fine") != std::string::npos);
    CHECK_FALSE(std::filesystem::exists(dir / "new"));
    // A directory that was there before stays, with what it held.
    std::filesystem::create_directories(dir / "kept");
    std::ofstream(dir / "kept" / "notes.txt") << "mine";
    r = run_sample("box --spacing 1e-5 --out '" + (dir / "kept").string() + "'", kGuard);
    CHECK(r.code == 2);
    CHECK(read_file(dir / "kept" / "notes.txt") == "mine");
    std::filesystem::remove_all(dir);
}

MW_TEST_MAIN
