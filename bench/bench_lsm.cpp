// LSM step time for elastic (w = 2) and rigid cubes of about 6k, 50k and 500k IBPs on each
// available backend: median ms of the "lsm" stage (regions + polar, goals + update, GPs, SBPs, NaN
// guard). A rigid cube is one region over all its IBPs, the case the chunked region sums are for.
// Usage: bench_lsm [max_ibps=600000] [steps=20]
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "apps/scene_builder.hpp"
#include "simulation/factory.hpp"
#include "sampling/procedural_meshes.hpp"

using namespace mw;

static double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0 : v[v.size() / 2];
}

int main(int argc, char** argv) {
    const char* usage = "usage: bench_lsm [max_ibps=600000] [steps=20]\n";
    if (argc > 3 || (argc > 1 && (std::string(argv[1]) == "--help" || std::string(argv[1]) == "-h"))) {
        std::fprintf(argc > 3 ? stderr : stdout, "%s", usage);
        return argc > 3 ? 2 : 0;
    }
    char* end = nullptr;
    const double max_ibps = argc > 1 ? std::strtod(argv[1], &end) : 600000;
    if (argc > 1 && (*end != '\0' || !(max_ibps > 0))) {
        std::fprintf(stderr, "bench_lsm: max_ibps must be a positive number, got '%s'\n%s", argv[1], usage);
        return 2;
    }
    const long steps_given = argc > 2 ? std::strtol(argv[2], &end, 10) : 20;
    if (argc > 2 && (*end != '\0' || steps_given < 1 || steps_given > 100000)) {
        std::fprintf(stderr, "bench_lsm: steps must be an integer in [1, 100000], got '%s'\n%s", argv[2], usage);
        return 2;
    }
    const int steps = static_cast<int>(steps_given);
    const Real r0 = Real(0.02);
    std::printf("| solid | IBPs | SBPs | GPs | backend | device | ms_lsm (median of %d steps) | setup s |\n|---|---|---|---|---|---|---|---|\n", steps);
    for (int side : {18, 37, 80}) {
        if (double(side) * side * side > max_ibps) break;
        for (SolidKind kind : {SolidKind::kElastic, SolidKind::kRigid}) {
            const auto t0 = std::chrono::steady_clock::now();
            SimulationSetup s;
            const Real L = side * r0;
            s.params.domain_min = Vec3{0, 0, 0};
            s.params.domain_max = Vec3{L + 0.2f, L + 0.2f, L + 0.2f};
            s.params.fluid.spacing = r0;
            s.params.fluid.support_radius = Real(0.05);
            s.params.solver.dt = Real(0.005);
            s.params.boundary.walls = false;  // the cube alone: LSM keeps it inside the domain box
            TriangleMesh mesh = make_box(Vec3d(L, L, L));
            MeshTransform t;
            t.translation = Vec3d(0.1 + L / 2, 0.1 + L / 2, 0.1 + L / 2);
            apply_transform(mesh, t);
            SolidSetup solid;
            solid.name = "cube";
            solid.kind = kind;
            solid.stiffness = Real(0.5);
            solid.region_half_width = 2;
            add_solid_object(s, mesh, solid, Vec3{0, 0, 0}, 0, r0, 0.05);
            const double setup_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
            const SolidSetup& o = s.solids[0];
            std::vector<std::pair<std::string, bool>> backends{{"openmp", true}, {"cuda", cuda_backend_info().available}};
            for (const auto& [name, ok] : backends) {
                if (!ok) continue;
                auto sim = name == "openmp" ? create_openmp_simulation(s, 0) : create_cuda_simulation(s);
                const auto names = sim->stage_names();
                const std::size_t lsm = std::find(names.begin(), names.end(), "lsm") - names.begin();
                std::vector<double> ms;
                for (int k = 0; k < steps + 3; ++k) {
                    sim->step();
                    if (k >= 3) ms.push_back(sim->last_report().stage_ms[lsm]);
                }
                std::printf("| %s | %zu | %zu | %zu | %s | %s | %.3f | %.1f |\n", kind == SolidKind::kRigid ? "rigid" : "elastic", o.ibp.size(), o.sbp.size(), o.gp.size(), name.c_str(),
                            sim->device_name().c_str(), median(ms), setup_s);
                std::fflush(stdout);
            }
        }
    }
    return 0;
}
