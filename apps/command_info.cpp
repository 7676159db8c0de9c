// `meltwater info [SCENE]`: what a run of the scene would create and run, without running it.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "apps/run_estimate.hpp"
#include "apps/scene_builder.hpp"
#include "apps/speed_limit.hpp"
#include "algorithms/solid_obstacles.hpp"
#include "simulation/factory.hpp"
#include "common/errors.hpp"
#include "sampling/wall_gap.hpp"

namespace mw {

namespace {

// What `info` reports, gathered once for the text and the JSON forms.
struct InfoFacts {
    Scene scene;
    std::string backend;
    SimulationSetup setup;
    long carved_fluid = 0;
    ParticleCounts counts;
    std::unique_ptr<Simulation> probe;
    std::size_t bytes = 0;
    double bytes_per_particle = 0;
    SpeedLimit runaway;
    std::vector<std::string> stages, warnings;
    long frames = 0;
    long moving_objects = 0;
    DiskEstimate disk;
    TimeEstimate time;
    std::string time_note;  // why no time was measured ("" when it was)
};

// Times `steps` steps on the backend a run would use: the host probe is an OpenMP simulation; a
// CUDA run is timed on the GPU when there is one.
void measure_time(InfoFacts& f, int steps) {
    if (steps <= 0) {
        f.time_note = "not measured (--time-steps 0)";
        return;
    }
    if (f.backend == "openmp") {
        f.time = time_steps(*f.probe, f.scene, f.scene.end_time, steps);
        return;
    }
    if (!cuda_backend_info().available) {
        f.time_note = "not measured: no GPU here for the cuda backend";
        return;
    }
    const std::unique_ptr<Simulation> sim = create_simulation(f.setup, "cuda", 0);
    f.time = time_steps(*sim, f.scene, f.scene.end_time, steps);
}

InfoFacts gather(const Scene& scene, const std::string& backend) {
    InfoFacts f;
    f.scene = scene;
    f.backend = backend;
    check_host_memory(scene, backend, true);
    f.setup = build_setup(scene, &f.carved_fluid);
    f.counts = count_particles(f.setup);
    f.probe = probe_on_host(f.setup, backend);
    f.bytes = f.probe->device_bytes();
    f.runaway = speed_limit(scene, f.setup);
    f.stages = f.probe->stage_names();
    f.bytes_per_particle = f.counts.total() ? double(f.bytes) / double(f.counts.total()) : 0.0;
    const std::string heat_warning = heat_substeps_warning(
        f.probe->heat_substeps_needed(double(scene.params.solver.dt)), scene.params.heat.max_substeps);
    for (const std::string& warning : {scene.kernel_warning(), heat_warning, emitter_overlap_warning(f.setup)})
        if (!warning.empty()) f.warnings.push_back(warning);
    f.frames = scene.writes_frames() ? 1 + static_cast<long>(std::floor(scene.end_time * scene.fps + 1e-9)) : 0;
    f.moving_objects = std::count_if(scene.objects.begin(), scene.objects.end(),
                                     [](const SceneObject& o) { return o.kind != SolidKind::kStatic; });
    f.disk = estimate_disk(scene, f.counts, f.setup);
    return f;
}

void print_json(const InfoFacts& f) {
    const Scene& scene = f.scene;
    SceneJson j;
    j["scene_name"] = scene.name;
    j["scene_source"] = scene.source;
    SceneJson p;
    for (int t = 0; t < kParticleTypeCount; ++t) p[particle_type_name(t)] = f.counts.by_type[t];
    p["total"] = f.counts.total();
    j["particles"] = p;
    j["fluid_carved"] = f.carved_fluid;
    if (scene.walls()) j["wall_gap_m"] = scene.wall_gap();  // the first wall layer's distance outside the faces
    j["warnings"] = f.warnings;
    j["backend"] = f.backend;
    j["device_bytes"] = f.bytes;
    j["bytes_per_particle"] = f.bytes_per_particle;
    j["stages"] = f.stages;
    if (scene.params.heat.enabled)  // the sub-steps the largest step needs, before heat.max_substeps
        j["heat_substeps_needed"] = f.probe->heat_substeps_needed(double(scene.params.solver.dt));
    j["frames"] = f.frames;
    SceneJson disk;
    for (const auto& [name, bytes] : f.disk.parts) disk[name] = bytes;
    j["disk_estimate"] = {{"bytes", f.disk.total}, {"by_kind", disk}, {"surface_from_start", f.disk.surface_estimated}};
    if (f.time.steps_timed > 0)
        j["time_estimate"] = {{"steps_timed", f.time.steps_timed}, {"ms_per_step", f.time.ms_per_step},
                              {"steps_to_end", f.time.steps_to_end}, {"seconds", f.time.seconds},
                              {"lower_bound", f.time.lower_bound}};
    else
        j["time_estimate"] = nullptr;
    j["speed_limit"] = f.runaway.limit > 0 ? SceneJson(f.runaway.limit) : SceneJson(nullptr);  // m/s
    if (!f.setup.emitters.empty()) {
        SceneJson list = SceneJson::array();
        for (const EmitterSetup& e : f.setup.emitters)
            list.push_back({{"name", e.name}, {"per_layer", e.offsets.size()}, {"layers", e.layers},
                            {"particles", std::size_t(e.layers) * e.offsets.size()}});
        j["emitters"] = list;
    }
    if (!f.setup.pressure_sensors.empty()) {
        SceneJson list = SceneJson::array();
        for (const PressureSensorSetup& p : f.setup.pressure_sensors)
            list.push_back({{"name", p.name}, {"axis", p.axis}, {"side", p.side}, {"size", double(p.size)}});
        j["pressure_sensors"] = list;
    }
    j["scene"] = scene.resolved;
    std::printf("%s\n", j.dump(2, ' ', false, SceneJson::error_handler_t::replace).c_str());
}

void print_counts(const InfoFacts& f) {
    const Scene& scene = f.scene;
    std::printf("scene       %s (%s)\n", scene.name.empty() ? "(unnamed)" : scene.name.c_str(), scene.source.c_str());
    std::printf("particles  ");
    for (int t = 0; t < kParticleTypeCount; ++t)
        if (t != kPending || f.counts.by_type[t] > 0)  // pending: only where an emitter holds some
            std::printf(" %s %s |", particle_type_name(t), with_thousands(f.counts.by_type[t]).c_str());
    std::printf(" total %s\n", with_thousands(f.counts.total()).c_str());
    if (f.carved_fluid > 0)
        std::printf("carved      %s fluid particles left out where static boxes and objects stand (closer than "
                    "%g r0 to their particles, or inside a box)\n",
                    with_thousands(f.carved_fluid).c_str(), kFluidClearance);
    std::printf("memory      %s on the %s backend (%.0f bytes/particle; its layout, measured on the host)\n",
                format_bytes(double(f.bytes)).c_str(), f.backend.c_str(), f.bytes_per_particle);
    std::printf("stages     ");
    for (std::size_t i = 0; i < f.stages.size(); ++i) std::printf("%s %s", i ? "," : "", f.stages[i].c_str());
    std::printf("\n");
}

// The disk the frames take and the time the steps take (apps/run_estimate.hpp).
void print_estimates(const InfoFacts& f) {
    std::string parts;
    for (const auto& [name, bytes] : f.disk.parts) parts += (parts.empty() ? "" : ", ") + name + " " + format_bytes(bytes);
    if (f.disk.frames > 0)
        std::printf("disk        about %s for %s: %s%s\n", format_bytes(f.disk.total).c_str(),
                    count_of(f.disk.frames, "frame").c_str(), parts.c_str(),
                    f.disk.surface_estimated ? " (surfaces sized from the fluid's start; splashes enlarge them)" : "");
    else
        std::printf("disk        no frames (output.formats is empty): stats.csv and summary.json only\n");
    if (f.time.steps_timed == 0) {
        std::printf("time        %s\n", f.time_note.c_str());
        return;
    }
    std::printf("time        %.3g ms/step over %d steps timed here on %s; %s%s steps to t=%g s: about %s%s\n",
                f.time.ms_per_step, f.time.steps_timed, f.backend.c_str(), f.time.lower_bound ? "at least " : "",
                with_thousands(long(f.time.steps_to_end)).c_str(), f.scene.end_time,
                format_duration(f.time.seconds).c_str(),
                f.time.lower_bound ? " or more (CFL steps shorten as the fluid speeds up)" : "");
}

void print_fluid_and_run(const InfoFacts& f) {
    const Scene& scene = f.scene;
    const FluidParams& fp = scene.params.fluid;
    const SolverParams& solver = scene.params.solver;
    // Whether the viscosity stage runs is the simulation's decision (it also needs fluid, and wall
    // friction needs walls), so it is read from the stage list rather than guessed from the keys.
    const bool runs_viscosity = std::find(f.stages.begin(), f.stages.end(), "viscosity") != f.stages.end();
    std::printf("fluid       r0 %g m, h %g m (%.3g r0, %s kernel), rest density %g kg/m3, viscosity %g Pa s, wall "
                "viscosity %g Pa s%s\n",
                double(fp.spacing), double(fp.support_radius), double(fp.support_radius / fp.spacing),
                kernel_name(fp.kernel), double(fp.rest_density), double(fp.viscosity), double(fp.wall_viscosity),
                runs_viscosity ? "" : " (viscosity stage off)");
    char stopping_rule[96];
    if (solver.eta_max > 0)
        std::snprintf(stopping_rule, sizeof stopping_rule, "density error < %g average, < %g peak", double(solver.eta),
                      double(solver.eta_max));
    else
        std::snprintf(stopping_rule, sizeof stopping_rule, "density error < %g average (peak unbounded)", double(solver.eta));
    if (solver.dt_mode == TimeStepMode::kCfl)
        std::printf("solver      CFL time step (number %g, at most %g s), %s, %d..%d iterations\n",
                    double(solver.cfl_number), double(solver.dt), stopping_rule, solver.min_iterations,
                    solver.max_iterations);
    else
        std::printf("solver      fixed time step %g s (%s to t=%g s), %s, %d..%d iterations\n", double(solver.dt),
                    count_of(static_cast<long>(std::ceil(scene.end_time / solver.dt - 1e-9)), "step").c_str(),
                    scene.end_time, stopping_rule, solver.min_iterations, solver.max_iterations);
    std::printf("run         to t=%g s; %s (%g per simulated second)\n", scene.end_time,
                count_of(f.frames, "frame").c_str(), scene.fps);
    std::printf("guards      the run stops at a peak density error above %g (solver.max_density_error)",
                scene.max_density_error);
    if (scene.max_lost_fraction < 1)
        std::printf("; more than %g%% of the fluid lost (boundary.max_lost_fraction)", 100 * scene.max_lost_fraction);
    if (f.runaway.limit > 0) std::printf("; a particle faster than %s\n", describe(f.runaway).c_str());
    else std::printf("; no speed limit (solver.max_speed: no gravity, motion or emitter to scale one by)\n");
    print_estimates(f);
    if (scene.writes_surface())
        std::printf("surface     the fluid's surface with every frame (frames/surface_NNNNN.obj): its colour field on "
                    "nodes %g r0 apart, meshed%s\n",
                    scene.surface_voxel, scene.writes_vtu() ? "" : " (no particle frames: output.formats has no \"vtu\")");
}

// What the walls' correction covers, and where it stops the fluid (algorithms/wall_contact.hpp).
void print_boundary(const InfoFacts& f) {
    const Scene& scene = f.scene;
    const FluidParams& fp = scene.params.fluid;
    if (scene.walls())
        std::printf("boundary    domain walls, %d layer(s) at %g m, the first %.3g r0 outside the faces (where fluid "
                    "next to a face starts at rest density for h %.3g r0); %zu static box(es)\n",
                    scene.boundary_layers, double(scene.boundary_spacing()), double(scene.wall_gap() / fp.spacing),
                    double(fp.support_radius / fp.spacing), scene.static_boxes.size());
    else
        std::printf("boundary    no domain walls; %zu static box(es)\n", scene.static_boxes.size());
    const bool boxes = !scene.static_boxes.empty();
    // Static objects the correction covers: those with a distance grid (none without fluid).
    const long static_objects = long(f.setup.params.boundary.static_objects.size());
    const bool any_static_object = std::any_of(scene.objects.begin(), scene.objects.end(),
                                               [](const SceneObject& o) { return o.kind == SolidKind::kStatic; });
    if (!(scene.walls() || boxes || static_objects || any_static_object)) return;
    if (!scene.params.boundary.correction) {
        std::printf("            velocity-position correction off (boundary.correction false): only the Akinci "
                    "layers hold the fluid in\n");
        return;
    }
    std::string covered, coarse_grid_warning;
    auto add = [&](const std::string& part) { covered += (covered.empty() ? "" : ", ") + part; };
    if (scene.walls()) add("about r0 from the walls' layer");
    if (boxes) add("about r0 from a static box");
    if (static_objects) {
        std::size_t nodes = 0;
        double coarsest = 0;
        for (const ContactField& c : f.setup.params.boundary.static_objects) {
            nodes += std::size_t(c.field.nx) * std::size_t(c.field.ny) * std::size_t(c.field.nz);
            coarsest = std::max(coarsest, 1 / double(c.field.inv_spacing));
        }
        char part[200];
        std::snprintf(part, sizeof part,
                      "%.2g r0 from a static object's surface (%ld object(s); distance grids of %zu nodes, %.1f MiB, "
                      "spacing up to %.3g r0)",
                      kStaticObjectContact, static_objects, nodes, double(nodes * sizeof(Real)) / (1 << 20),
                      coarsest / double(fp.spacing));
        add(part);
        if (coarsest > 0.5 * double(fp.spacing) * (1 + 1e-6))
            coarse_grid_warning = "a static object's distance grid is coarser than r0/2 (" +
                                  std::to_string(coarsest / double(fp.spacing)) + " r0: more than " +
                                  std::to_string(kMaxObjectDistanceNodes) +
                                  " nodes at r0/2), so the correction is less exact at its edges";
    }
    if (!static_objects && !scene.walls() && !boxes) return;
    std::printf("            velocity-position correction on (boundary.correction): fluid moving into a boundary "
                "stops %s\n",
                covered.c_str());
    if (!coarse_grid_warning.empty()) std::printf("warning     %s\n", coarse_grid_warning.c_str());
}

// How the fluid and the moving objects act on each other (docs/coupling.md).
void print_coupling(const InfoFacts& f) {
    const Scene& scene = f.scene;
    const CouplingParams& c = scene.params.coupling;
    if (!f.moving_objects || !scene.has_fluid()) return;
    if (c.two_way)
        std::printf("coupling    two-way (coupling.two_way): the fluid's pressure%s acts back on %ld moving object(s), "
                    "through their LSM regions\n",
                    scene.params.fluid.wall_viscosity > 0 ? " and friction" : "", f.moving_objects);
    else
        std::printf("coupling    one-way (coupling.two_way false): %ld moving object(s) push the fluid and feel none "
                    "of it\n",
                    f.moving_objects);
    const bool solid_kind = std::any_of(scene.objects.begin(), scene.objects.end(), [](const SceneObject& o) {
        return o.kind == SolidKind::kRigid || (o.kind == SolidKind::kElastic && !o.melts());
    });
    // Rigid and elastic objects' surface particles set in (sampling/surface_inset.hpp; an open mesh's are not);
    // the correction's band follows (algorithms/wall_contact.hpp, moving_solid_contact).
    const bool set_in = f.setup.any_sbp_set_in();
    if (set_in) {
        const FluidParams& fp = scene.params.fluid;
        const double inset = rest_density_wall_gap(fp.spacing, fp.support_radius, fp.spacing / 2, 1, fp.kernel);
        std::printf("            rigid and elastic ones' surface particles sit %.2f r0 inside their faces, where the fluid rests as "
                    "at a wall (coupling.surface_inset)\n",
                    inset / double(fp.spacing));
    }
    else if (solid_kind)
        std::printf("            rigid and elastic ones' surface particles sit on their faces (%s): the fluid rests about one r0 "
                    "off them\n",
                    c.surface_inset ? "their meshes are open: no inside to set them into" : "coupling.surface_inset false");
    if (c.correction)
        std::printf("            velocity-position correction against them on (coupling.correction): fluid moving into "
                    "one stops %.2f r0 from its surface%s, slip %g\n",
                    moving_solid_contact(f.setup.narrow_solid_band()),
                    c.two_way ? " and trades momentum with it" : " and takes its velocity", double(c.slip));
    else
        std::printf("            velocity-position correction against them off (coupling.correction false)\n");
    if (c.predict_solids) {
        std::printf("            PCISPH meets them where they will be at the end of the step (coupling.predict_solids): "
                    "rigid ones, cloths and rods at their particles' velocity, soft ones at their mean velocity\n");
        const bool cloth = std::any_of(scene.objects.begin(), scene.objects.end(),
                                       [](const SceneObject& o) { return is_thin(o.kind); });
        const char* answering = solid_kind && cloth ? "rigid and solid elastic ones (each as one body) and the cloths' and rods' nodes"
                                : solid_kind        ? "rigid and solid elastic ones, each as one body,"
                                                    : "the cloths' and rods' nodes";
        if ((solid_kind || cloth) && c.two_way && c.strong)
            std::printf("            %s answer the fluid's pressure inside every PCISPH iteration (coupling.strong)\n",
                        answering);
        else if ((solid_kind || cloth) && c.two_way)
            std::printf("            %s feel the fluid's pressure only after PCISPH (coupling.strong false): it is "
                        "solved as if they kept their velocity\n",
                        answering);
    } else
        std::printf("            PCISPH meets them where they start the step (coupling.predict_solids false): one "
                    "entering the fluid fast can blow it up\n");
    const long with_tension = std::count_if(scene.objects.begin(), scene.objects.end(),
                                            [](const SceneObject& o) { return o.interface_tension > 0; });
    if (with_tension)
        std::printf("            interface tension (Eq. 9) between the fluid and %ld object(s)\n", with_tension);
}

// Emitters (algorithms/emitter.hpp): what each releases, and when; pressure sensors; heat
// conduction (docs/heat.md).
// What the moving objects meet (docs/contact.md).
void print_contact(const InfoFacts& f) {
    if (!f.moving_objects) return;
    const BoundaryParams& b = f.setup.params.boundary;
    std::printf("contact     moving objects meet the domain's faces, %zu static box(es), %zu static object(s)%s "
                "(docs/contact.md)\n",
                b.static_boxes.size(), b.static_objects.size(),
                f.moving_objects < 2 ? ""
                : f.setup.params.solver.solid_contact
                    ? (" and one another, in " + std::to_string(kCollisionIterations) + " Jacobi sweeps a substep").c_str()
                    : ", not one another (solver.solid_contact false)");
    if (f.setup.keeps_wall_film())
        std::printf("            with fluid, those that start clear of them stop a fluid layer (1.5 r0) short of the walls and "
                    "static boxes (coupling.wall_film)\n");
}

void print_emitters_and_heat(const InfoFacts& f) {
    const Scene& scene = f.scene;
    const FluidParams& fp = scene.params.fluid;
    static const char* const kFaces[3][2] = {{"x min", "x max"}, {"y min", "y max"}, {"z min", "z max"}};
    for (std::size_t k = 0; k < f.setup.pressure_sensors.size(); ++k) {
        const PressureSensorSetup& p = f.setup.pressure_sensors[k];
        std::printf("%s %s: the %s face, %g m square at [%g, %g, %g] (stats.csv sensor_%s, Pa)\n",
                    k ? "           " : "sensors    ", p.name.c_str(), kFaces[p.axis][p.side > 0 ? 1 : 0],
                    double(p.size), double(p.center.x), double(p.center.y), double(p.center.z), p.name.c_str());
    }
    for (std::size_t k = 0; k < f.setup.emitters.size(); ++k) {
        const EmitterSetup& e = f.setup.emitters[k];
        const double interval = double(fp.spacing) / double(e.speed);
        const double count = double(e.layers) * double(e.offsets.size());
        // Each particle stands for a lattice cell r0^3 of fluid at rest.
        std::printf("%s %s: %zu particles a layer at %g m/s, a layer every %.4g s from t=%g s, %s layers "
                    "(%s particles, %.4g m3 at rest; the last at t=%.4g s)\n",
                    k ? "           " : "emitters   ", e.name.c_str(), e.offsets.size(), double(e.speed), interval,
                    e.start, with_thousands(long(e.layers)).c_str(), with_thousands(long(count)).c_str(),
                    count * double(fp.spacing) * double(fp.spacing) * double(fp.spacing),
                    e.start + double(e.layers - 1) * interval);
    }
    if (!scene.params.heat.enabled) return;
    const SolverParams& solver = scene.params.solver;
    const std::string who = (!scene.has_fluid() ? std::string("") : std::string("the fluid and ")) +
                            std::to_string(f.moving_objects) + " moving object(s)";
    std::printf("heat        conduction on (heat.enabled) among %s; walls, static boxes and static objects are "
                "adiabatic; Fourier number alpha dt / r0^2 up to %.3g at the largest step: %d sub-step(s) a step (at "
                "most %d)\n",
                who.c_str(), scene.largest_heat_diffusivity() * double(solver.dt) / (double(fp.spacing) * double(fp.spacing)),
                std::min(f.probe->heat_substeps_needed(double(solver.dt)), scene.params.heat.max_substeps),
                scene.params.heat.max_substeps);
}

}  // namespace

int command_info(int argc, char** argv) {
    cxxopts::Options options("meltwater info",
                             "Particle counts by type, the memory estimate and the stages a run of SCENE\n"
                             "(the built-in 3D dam break when omitted) would use.");
    add_scene_options(options);
    options.add_options()("json", "print one JSON object instead of text")(
        "backend", "the backend whose memory layout to estimate: auto (what run would use), cuda or openmp",
        cxxopts::value<std::string>()->default_value("auto"), "NAME")(
        "time-steps", "steps to time for the run's time estimate (0: none)", cxxopts::value<int>()->default_value("3"),
        "N");
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
    const int time_steps_wanted = args["time-steps"].as<int>();
    if (time_steps_wanted < 0 || time_steps_wanted > 1000)
        throw InputError("--time-steps must be 0 to 1000, got " + std::to_string(time_steps_wanted));
    InfoFacts facts = gather(scene, requested == "auto" ? choose_backend("auto") : requested);
    measure_time(facts, time_steps_wanted);
    if (flag_option(args, "json")) {
        print_json(facts);
        return 0;
    }
    print_counts(facts);
    print_fluid_and_run(facts);
    print_boundary(facts);
    print_coupling(facts);
    print_contact(facts);
    print_emitters_and_heat(facts);
    for (const std::string& warning : facts.warnings) std::printf("warning     %s\n", warning.c_str());
    return 0;
}

}  // namespace mw
