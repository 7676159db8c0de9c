// The fluid's surface through the command line: output.formats "surface" and output.surface.voxel
// (docs/scenes.md), what `info` says and what a run writes. The meshes themselves are checked in
// tests/core/test_surface.cpp.
#include <doctest/doctest.h>

#include <filesystem>

#include "cli_helpers.hpp"
#include "tests/skip.hpp"

using namespace cli_test;
namespace fs = std::filesystem;

namespace {
std::string tiny_file() { return scene_file("surface_tiny.json", tiny_scene_text()); }

// The OBJ's vertex and face lines.
std::pair<long, long> obj_counts(const std::string& path) {
    std::istringstream in(slurp(path));
    std::string line;
    long vertices = 0, faces = 0;
    while (std::getline(in, line)) vertices += line.rfind("v ", 0) == 0, faces += line.rfind("f ", 0) == 0;
    return {vertices, faces};
}
}  // namespace

TEST_CASE("run: output.formats surface writes a closed mesh with every frame, and the same steps") {
    const std::string scene = tiny_file();
    const std::string with = out_dir("surface_with"), without = out_dir("surface_without");
    const std::string common = " --time 0.02 --backend openmp --threads 2 --quiet --set output.fps=100";
    const Result a = run("run " + scene + common + " --out " + with + " --set 'output.formats=[\"vtu\",\"surface\"]'");
    CAPTURE(a.err);
    REQUIRE(a.code == 0);
    CHECK(contains(a.out, "3 frames and 3 surfaces"));
    const Result b = run("run " + scene + common + " --out " + without);
    REQUIRE(b.code == 0);
    for (int f = 0; f < 3; ++f) {
        char name[64];
        std::snprintf(name, sizeof name, "/frames/surface_%05d.obj", f);
        CAPTURE(name);
        REQUIRE(fs::exists(with + name));
        const auto [vertices, faces] = obj_counts(with + name);
        CHECK(vertices > 100);
        CHECK(faces > 100);
        CHECK(!fs::exists(without + name));
    }
    CHECK(fs::exists(with + "/frames/particles_00002.vtu"));
    const auto s = read_json(with + "/summary.json");
    REQUIRE(s.contains("surface"));
    CHECK(s["surface"]["meshes"] == 3);
    CHECK(s["surface"]["ms_per_mesh"].get<double>() > 0);
    CHECK(s["surface"]["field_ms_per_mesh"].get<double>() <= s["surface"]["ms_per_mesh"].get<double>());
    CHECK(s["surface"]["triangles_last"].get<long>() == obj_counts(with + "/frames/surface_00002.obj").second);
    CHECK(s["scene"]["output"]["surface"]["voxel"].get<double>() == doctest::Approx(0.5));
    CHECK(!read_json(without + "/summary.json").contains("surface"));
    // Meshing the surface reorders nothing the next step would not: the steps are the same.
    CHECK(stats_without_timings(with + "/stats.csv") == stats_without_timings(without + "/stats.csv"));

    // Surfaces alone: no particle frames and no collection; a later run without them removes them.
    const std::string alone = out_dir("surface_alone");
    const Result c = run("run " + scene + common + " --out " + alone + " --set 'output.formats=[\"surface\"]'");
    CAPTURE(c.err);
    REQUIRE(c.code == 0);
    CHECK(fs::exists(alone + "/frames/surface_00000.obj"));
    CHECK(!fs::exists(alone + "/frames/particles_00000.vtu"));
    CHECK(!fs::exists(alone + "/frames/particles.pvd"));
    REQUIRE(run("run " + scene + " --steps 1 --quiet --out " + alone + " --set 'output.formats=[]'").code == 0);
    CHECK(!fs::exists(alone + "/frames/surface_00000.obj"));
}

TEST_CASE("checkpoint: a run with surfaces resumed half way writes the whole run's surfaces, byte for byte") {
    const std::string scene = tiny_file();
    const std::string options = " --backend openmp --quiet --set output.fps=100 --set 'output.formats=[\"surface\"]'";
    const std::string whole = out_dir("surface_ckpt_whole"), halves = out_dir("surface_ckpt_halves");
    Result r = run("run " + scene + options + " --threads 2 --steps 12 --out " + whole);
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    REQUIRE(run("run " + scene + options + " --threads 2 --steps 6 --checkpoint --out " + halves).code == 0);
    // Resumed on one thread: neither the field nor the mesher depends on the thread count.
    r = run("run --resume " + halves + "/checkpoint.mwc --steps 6 --threads 1 --quiet");
    REQUIRE(r.code == 0);
    int compared = 0;
    for (const auto& entry : fs::directory_iterator(whole + "/frames")) {
        const std::string name = entry.path().filename().string();
        CAPTURE(name);
        REQUIRE(fs::exists(halves + "/frames/" + name));
        CHECK(slurp(entry.path().string()) == slurp(halves + "/frames/" + name));
        compared += name.rfind("surface_", 0) == 0;
    }
    CHECK(compared == 3);  // 12 steps of 2 ms: frames at t = 0, 0.01 and 0.02 s
}

TEST_CASE("info: the surface line names its node spacing") {
    const Result r = run("info " + tiny_file() + " --set 'output.formats=[\"surface\"]' --set output.surface.voxel=0.25");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    CHECK(contains(r.out, "surface "));
    CHECK(contains(r.out, "0.25 r0 apart"));
    CHECK(contains(r.out, "no particle frames"));
    CHECK(!contains(run("info " + tiny_file()).out, "surface "));
}

TEST_CASE("bad input: surface output keys") {
    const std::string scene = tiny_file();
    check_rejected(run("info " + scene + " --set 'output.formats=[\"stl\"]'"), {"output.formats", "stl"});
    check_rejected(run("info " + scene + " --set output.surface.voxel=0.05"), {"output.surface.voxel"});
    check_rejected(run("info " + scene + " --set output.surface.voxel=5"), {"output.surface.voxel"});
    check_rejected(run("info " + scene + " --set output.surface.size=1"), {"output.surface.size"});
    // A voxel whose node box over the domain could pass the per-frame limit, refused before the run.
    check_rejected(run("run " + scene + " --steps 1 --out " + out_dir("surface_huge") +
                       " --set 'output.formats=[\"surface\"]' --set 'domain.max=[40,40,40]' --set output.surface.voxel=0.1"),
                   {"output.surface.voxel", "nodes"});
    CHECK(!fs::exists(scratch_dir() + "/surface_huge"));
}

TEST_CASE("run: the surface as PLY and the fluid as OpenVDB grids read back with meshio and pyopenvdb") {
    // Debian's meshio and pyopenvdb live under /usr/bin/python3, which another python3 on PATH may hide.
    std::string python;
    for (const char* candidate : {"/usr/bin/python3", "python3"})
        if (python.empty() &&
            std::system((std::string(candidate) + " -c 'import meshio, pyopenvdb' >/dev/null 2>&1").c_str()) == 0)
            python = candidate;
    if (python.empty()) {
        MW_SKIP("python3 with meshio and pyopenvdb is missing (apt install python3-meshio python3-openvdb)");
        return;
    }
    const std::string dir = out_dir("surface_vdb");
    const Result r = run("run " + tiny_file() + " --steps 1 --quiet --out " + dir +
                         " --set 'output.formats=[\"surface\",\"ply\",\"vdb\"]'");
    CAPTURE(r.err);
    REQUIRE(r.code == 0);
    const auto [vertices, faces] = obj_counts(dir + "/frames/surface_00000.obj");
    // The tiny scene's fluid: 125 particles r0 = 0.02 apart at 0.01 .. 0.09, whose surface sits
    // r0/2 outside the last layer: the block [0, 0.1]^3, after one step still.
    const std::string script = scratch_dir() + "/read_vdb.py";
    write_text(script,
               "import sys, meshio, pyopenvdb, numpy\n"
               "frames, vertices, faces = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])\n"
               "mesh = meshio.read(frames + '/surface_00000.ply')\n"
               "assert len(mesh.points) == vertices, (len(mesh.points), vertices)\n"
               "assert sum(len(c.data) for c in mesh.cells if c.type == 'triangle') == faces\n"
               "grids, meta = pyopenvdb.readAll(frames + '/fluid_00000.vdb')\n"
               "by_name = {g.name: g for g in grids}\n"
               "surface, density = by_name['surface'], by_name['density']\n"
               "assert surface.gridClass == 'level set' and density.gridClass == 'fog volume'\n"
               "xf = lambda g, p: tuple(int(round(c)) for c in g.transform.worldToIndex(p))\n"
               "inside = surface.getConstAccessor().getValue(xf(surface, (0.05, 0.05, 0.05)))\n"
               "outside = surface.getConstAccessor().getValue(xf(surface, (0.05, 0.14, 0.05)))\n"
               "near = surface.getConstAccessor().getValue(xf(surface, (0.05, 0.11, 0.05)))\n"
               "assert inside < 0 < outside, (inside, outside)\n"
               "assert abs(near - 0.01) < 0.006, near  # metres to the face at y = 0.1\n"
               "d = density.getConstAccessor().getValue(xf(density, (0.05, 0.05, 0.05)))\n"
               "assert 0.9 < d <= 1.0, d\n"
               "print('ok')\n");
    const std::string log = scratch_dir() + "/read_vdb.log";
    const int status = std::system((python + " '" + script + "' '" + dir + "/frames' " + std::to_string(vertices) + " " +
                                    std::to_string(faces) + " >'" + log + "' 2>&1")
                                       .c_str());
    CAPTURE(slurp(log));
    CHECK(status == 0);
    CHECK(contains(slurp(log), "ok"));
}
