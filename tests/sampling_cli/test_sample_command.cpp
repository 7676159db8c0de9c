// `meltwater sample` end to end: output files and their fields, and one clear error with a
// non-zero exit for every kind of bad input.
#define DOCTEST_CONFIG_IMPLEMENT_WITH_MAIN
#include <doctest/doctest.h>

#include <sys/wait.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace {

struct Run {
    int code = -1;
    std::string output;  // stdout and stderr together
};

Run run_sample(const std::string& args) {
    const std::string cmd = std::string("OMP_NUM_THREADS=2 '") + MW_BINARY + "' sample " + args + " 2>&1";
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

std::string read_file(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

std::filesystem::path temp_dir(const std::string& name) {
    const auto d = std::filesystem::temp_directory_path() / ("mw_sample_cli_" + name);
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
        MESSAGE("SKIPPED: " << bunny << " is absent (the shared meshes live in ../shared/assets/meshes)");
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
    const std::string tet = "f 1 3 2\nf 1 2 4\nf 2 3 4\nf 3 1 4\n";
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
    };
    for (const Case& c : cases) {
        const Run r = run_sample(c.args);
        INFO(c.args << "\n" << r.output);
        CHECK(r.code == 2);
        CHECK(r.output.rfind("meltwater: error: ", 0) == 0);
        CHECK(r.output.find(c.expect) != std::string::npos);
        CHECK(std::count(r.output.begin(), r.output.end(), '\n') == 1);
    }
    CHECK_FALSE(std::filesystem::exists(dir / "out"));
    std::filesystem::remove_all(dir);
}
