// `meltwater info [SCENE]`: what a run of the scene would create and run, without running it.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "apps/scene_builder.hpp"
#include "apps/speed_limit.hpp"
#include "simulation/factory.hpp"
#include "common/errors.hpp"

namespace mw {

int command_info(int argc, char** argv) {
    cxxopts::Options options("meltwater info",
                             "Particle counts by type, the memory estimate and the stages a run of SCENE\n"
                             "(the built-in 3D dam break when omitted) would use.");
    add_scene_options(options);
    options.add_options()("json", "print one JSON object instead of text")(
        "backend", "the backend whose memory layout to estimate: auto (what run would use), cuda or openmp",
        cxxopts::value<std::string>()->default_value("auto"), "NAME");
    std::vector<std::string> overrides;
    const cxxopts::ParseResult args = parse_options(options, argc, argv, &overrides);
    if (flag_option(args, "help")) {
        std::printf("%s\n", options.help().c_str());
        return 0;
    }
    const Scene scene = scene_from_options(args, overrides);
    // The estimate is measured on the host backend with the target backend's layout; a GPU need
    // not be present to estimate for one.
    const std::string requested = args["backend"].as<std::string>();
    if (requested != "auto" && requested != "cuda" && requested != "openmp")
        throw InputError("--backend: expected auto, cuda or openmp, got '" + requested + "'");
    const std::string backend = requested == "auto" ? choose_backend("auto") : requested;
    check_host_memory(scene, backend, true);
    long carved_fluid = 0;
    const SimulationSetup setup = build_setup(scene, &carved_fluid);
    const ParticleCounts counts = count_particles(setup);
    const std::unique_ptr<Simulation> probe = probe_on_host(setup, backend);
    const std::size_t bytes = probe->device_bytes();
    const SpeedLimit runaway = speed_limit(scene, setup);
    const std::string emitter_warning = emitter_overlap_warning(setup);
    const std::vector<std::string> stages = probe->stage_names();
    const double bytes_per_particle = counts.total() ? double(bytes) / double(counts.total()) : 0.0;
    const SolverParams& solver = scene.params.solver;
    const bool cfl = solver.dt_mode == TimeStepMode::kCfl;
    const Real wall_gap = scene.walls() ? scene.wall_gap() : Real(0);
    const std::string heat_warning =
        heat_substeps_warning(probe->heat_substeps_needed(double(solver.dt)), scene.params.heat.max_substeps);
    const long frames = scene.writes_frames() ? 1 + static_cast<long>(std::floor(scene.end_time * scene.fps + 1e-9)) : 0;

    if (flag_option(args, "json")) {
        SceneJson j;
        j["scene_name"] = scene.name;
        j["scene_source"] = scene.source;
        SceneJson p;
        for (int t = 0; t < kParticleTypeCount; ++t) p[particle_type_name(t)] = counts.by_type[t];
        p["total"] = counts.total();
        j["particles"] = p;
        j["fluid_carved"] = carved_fluid;
        if (scene.walls()) j["wall_gap_m"] = wall_gap;  // the first wall layer's distance outside the faces
        j["warnings"] = SceneJson::array();
        for (const std::string& warning : {scene.kernel_warning(), heat_warning, emitter_warning})
            if (!warning.empty()) j["warnings"].push_back(warning);
        j["backend"] = backend;
        j["device_bytes"] = bytes;
        j["bytes_per_particle"] = bytes_per_particle;
        j["stages"] = stages;
        if (scene.params.heat.enabled)  // the sub-steps the largest step needs, before heat.max_substeps
            j["heat_substeps_needed"] = probe->heat_substeps_needed(double(solver.dt));
        j["frames"] = frames;
        j["speed_limit"] = runaway.limit > 0 ? SceneJson(runaway.limit) : SceneJson(nullptr);  // m/s
        if (!setup.emitters.empty()) {
            SceneJson list = SceneJson::array();
            for (const EmitterSetup& e : setup.emitters)
                list.push_back({{"name", e.name}, {"per_layer", e.offsets.size()}, {"layers", e.layers},
                                {"particles", std::size_t(e.layers) * e.offsets.size()}});
            j["emitters"] = list;
        }
        j["scene"] = scene.resolved;
        std::printf("%s\n", j.dump(2, ' ', false, SceneJson::error_handler_t::replace).c_str());
        return 0;
    }

    std::printf("scene       %s (%s)\n", scene.name.empty() ? "(unnamed)" : scene.name.c_str(), scene.source.c_str());
    std::printf("particles  ");
    for (int t = 0; t < kParticleTypeCount; ++t)
        if (t != kPending || counts.by_type[t] > 0)  // pending: only where an emitter holds some
            std::printf(" %s %s |", particle_type_name(t), with_thousands(counts.by_type[t]).c_str());
    std::printf(" total %s\n", with_thousands(counts.total()).c_str());
    if (carved_fluid > 0)
        std::printf("carved      %s fluid particles left out where static boxes and objects stand (closer than "
                    "%g r0 to their particles, or inside a box)\n",
                    with_thousands(carved_fluid).c_str(), kFluidClearance);
    std::printf("memory      %s on the %s backend (%.0f bytes/particle; its layout, measured on the host)\n",
                format_bytes(double(bytes)).c_str(), backend.c_str(), bytes_per_particle);
    std::printf("stages     ");
    for (std::size_t i = 0; i < stages.size(); ++i) std::printf("%s %s", i ? "," : "", stages[i].c_str());
    std::printf("\n");
    const FluidParams& f = scene.params.fluid;
    // Whether the viscosity stage runs is the simulation's decision (it also needs fluid, and wall
    // friction needs walls), so it is read from the stage list rather than guessed from the keys.
    const bool runs_viscosity = std::find(stages.begin(), stages.end(), "viscosity") != stages.end();
    std::printf("fluid       r0 %g m, h %g m (%.3g r0, %s kernel), rest density %g kg/m3, viscosity %g Pa s, wall "
                "viscosity %g Pa s%s\n",
                double(f.spacing), double(f.support_radius), double(f.support_radius / f.spacing),
                kernel_name(f.kernel), double(f.rest_density), double(f.viscosity), double(f.wall_viscosity),
                runs_viscosity ? "" : " (viscosity stage off)");
    char stopping_rule[96];
    if (solver.eta_max > 0)
        std::snprintf(stopping_rule, sizeof stopping_rule, "density error < %g average, < %g peak", double(solver.eta),
                      double(solver.eta_max));
    else
        std::snprintf(stopping_rule, sizeof stopping_rule, "density error < %g average (peak unbounded)", double(solver.eta));
    if (cfl)
        std::printf("solver      CFL time step (number %g, at most %g s), %s, %d..%d iterations\n",
                    double(solver.cfl_number), double(solver.dt), stopping_rule, solver.min_iterations,
                    solver.max_iterations);
    else
        std::printf("solver      fixed time step %g s (%s to t=%g s), %s, %d..%d iterations\n", double(solver.dt),
                    count_of(static_cast<long>(std::ceil(scene.end_time / solver.dt - 1e-9)), "step").c_str(),
                    scene.end_time,
                    stopping_rule, solver.min_iterations, solver.max_iterations);
    std::printf("run         to t=%g s; %ld frames (%g per simulated second)\n", scene.end_time, frames, scene.fps);
    std::printf("guards      the run stops at a peak density error above %g (solver.max_density_error)",
                scene.max_density_error);
    if (scene.max_lost_fraction < 1)
        std::printf("; more than %g%% of the fluid lost (boundary.max_lost_fraction)", 100 * scene.max_lost_fraction);
    if (runaway.limit > 0) std::printf("; a particle faster than %s\n", describe(runaway).c_str());
    else std::printf("; no speed limit (solver.max_speed: no gravity, motion or emitter to scale one by)\n");
    if (scene.writes_surface())
        std::printf("surface     the fluid's surface with every frame (frames/surface_NNNNN.obj): its colour field on "
                    "nodes %g r0 apart, meshed%s\n",
                    scene.surface_voxel, scene.writes_vtu() ? "" : " (no particle frames: output.formats has no \"vtu\")");
    if (scene.walls())
        std::printf("boundary    domain walls, %d layer(s) at %g m, the first %.3g r0 outside the faces (where fluid "
                    "next to a face starts at rest density for h %.3g r0); %zu static box(es)\n",
                    scene.boundary_layers, double(scene.boundary_spacing()), double(wall_gap / f.spacing),
                    double(f.support_radius / f.spacing), scene.static_boxes.size());
    else
        std::printf("boundary    no domain walls; %zu static box(es)\n", scene.static_boxes.size());
    const bool boxes = !scene.static_boxes.empty();
    // Static objects the correction covers: those with a distance grid (none without fluid).
    const long static_objects = long(setup.params.boundary.static_objects.size());
    if ((scene.walls() || boxes || static_objects) && scene.params.boundary.correction) {
        // What the correction covers, and where it stops the fluid (algorithms/wall_contact.hpp).
        std::string covered, coarse_grid_warning;
        auto add = [&](const std::string& part) { covered += (covered.empty() ? "" : ", ") + part; };
        if (scene.walls()) add("about r0 from the walls' layer");
        if (boxes) add("about r0 from a static box");
        if (static_objects) {
            std::size_t nodes = 0;
            double coarsest = 0;
            for (const ContactField& c : setup.params.boundary.static_objects) {
                nodes += std::size_t(c.field.nx) * std::size_t(c.field.ny) * std::size_t(c.field.nz);
                coarsest = std::max(coarsest, 1 / double(c.field.inv_spacing));
            }
            char part[200];
            std::snprintf(part, sizeof part,
                          "%.2g r0 from a static object's surface (%ld object(s); distance grids of %zu nodes, "
                          "%.1f MiB, spacing up to %.3g r0)",
                          kStaticObjectContact, static_objects, nodes, double(nodes * sizeof(Real)) / (1 << 20),
                          coarsest / double(f.spacing));
            add(part);
            if (coarsest > 0.5 * double(f.spacing) * (1 + 1e-6))
                coarse_grid_warning = "a static object's distance grid is coarser than r0/2 (" +
                                      std::to_string(coarsest / double(f.spacing)) +
                                      " r0: more than " + std::to_string(kMaxObjectDistanceNodes) +
                                      " nodes at r0/2), so the correction is less exact at its edges";
        }
        std::printf("            velocity-position correction on (boundary.correction): fluid moving into a "
                    "boundary stops %s\n",
                    covered.c_str());
        if (!coarse_grid_warning.empty()) std::printf("warning     %s\n", coarse_grid_warning.c_str());
    } else if (scene.walls() || boxes ||
               std::any_of(scene.objects.begin(), scene.objects.end(),
                           [](const SceneObject& o) { return o.kind == SolidKind::kStatic; })) {
        std::printf("            velocity-position correction off (boundary.correction false): only the Akinci "
                    "layers hold the fluid in\n");
    }
    // Two-way coupling: whether the moving objects feel the fluid (docs/coupling.md).
    const long moving_objects = std::count_if(scene.objects.begin(), scene.objects.end(),
                                              [](const SceneObject& o) { return o.kind != SolidKind::kStatic; });
    if (moving_objects && scene.has_fluid()) {
        if (scene.params.coupling.two_way)
            std::printf("coupling    two-way (coupling.two_way): the fluid's pressure%s acts back on %ld moving "
                        "object(s), through their LSM regions\n",
                        f.wall_viscosity > 0 ? " and friction" : "", moving_objects);
        else
            std::printf("coupling    one-way (coupling.two_way false): %ld moving object(s) push the fluid and "
                        "feel none of it\n",
                        moving_objects);
        if (scene.params.coupling.correction)
            std::printf("            velocity-position correction against them on (coupling.correction): fluid moving "
                        "into one stops %.2f r0 from its surface%s, slip %g\n",
                        kMovingSolidContact,
                        scene.params.coupling.two_way ? " and trades momentum with it" : " and takes its velocity",
                        double(scene.params.coupling.slip));
        else
            std::printf("            velocity-position correction against them off (coupling.correction false)\n");
        if (scene.params.coupling.predict_solids)
            std::printf("            PCISPH meets them where they will be at the end of the step "
                        "(coupling.predict_solids): rigid ones at their particles' velocity, soft ones at "
                        "their mean velocity\n");
        else
            std::printf("            PCISPH meets them where they start the step (coupling.predict_solids false): "
                        "one entering the fluid fast can blow it up\n");
        long with_tension = 0;
        for (const SceneObject& o : scene.objects) with_tension += o.interface_tension > 0 ? 1 : 0;
        if (with_tension)
            std::printf("            interface tension (Eq. 9) between the fluid and %ld object(s)\n", with_tension);
    }
    // Emitters (algorithms/emitter.hpp): what each releases, and when.
    for (std::size_t k = 0; k < setup.emitters.size(); ++k) {
        const EmitterSetup& e = setup.emitters[k];
        const double interval = double(f.spacing) / double(e.speed);
        const double count = double(e.layers) * double(e.offsets.size());
        // Each particle stands for a lattice cell r0³ of fluid at rest.
        std::printf("%s %s: %zu particles a layer at %g m/s, a layer every %.4g s from t=%g s, %s layers "
                    "(%s particles, %.4g m3 at rest; the last at t=%.4g s)\n",
                    k ? "           " : "emitters   ", e.name.c_str(), e.offsets.size(), double(e.speed), interval,
                    e.start, with_thousands(long(e.layers)).c_str(), with_thousands(long(count)).c_str(),
                    count * double(f.spacing) * double(f.spacing) * double(f.spacing),
                    e.start + double(e.layers - 1) * interval);
    }
    // Heat conduction (docs/heat.md): who conducts, and the Fourier number that sets its sub-steps.
    if (scene.params.heat.enabled) {
        const std::string who = (!scene.has_fluid() ? std::string("") : std::string("the fluid and ")) +
                                std::to_string(moving_objects) + " moving object(s)";
        std::printf("heat        conduction on (heat.enabled) among %s; walls, static boxes and static objects are "
                    "adiabatic; Fourier number alpha dt / r0^2 up to %.3g at the largest step: %d sub-step(s) a "
                    "step (at most %d)\n",
                    who.c_str(),
                    scene.largest_heat_diffusivity() * double(solver.dt) / (double(f.spacing) * double(f.spacing)),
                    std::min(probe->heat_substeps_needed(double(solver.dt)), scene.params.heat.max_substeps),
                    scene.params.heat.max_substeps);
    }
    for (const std::string& warning : {scene.kernel_warning(), heat_warning, emitter_warning})
        if (!warning.empty()) std::printf("warning     %s\n", warning.c_str());
    return 0;
}

}  // namespace mw
