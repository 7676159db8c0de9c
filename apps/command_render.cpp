// `meltwater render RUN_DIR`: the pictures of a finished (or stopped) run's frames, as a run with
// output.formats "preview" would have drawn them: frames/particles_NNNNN.vtu with the objects'
// meshes and the fluid's surface of the same frame where the run wrote them, the camera and
// colour field of the run's scene (summary.json) unless options say otherwise.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <unistd.h>

#include "apps/atomic_file.hpp"
#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "apps/frame_writer.hpp"
#include "apps/preview_picture.hpp"
#include "apps/scene_json.hpp"
#include "apps/speed_limit.hpp"
#include "apps/vtu_reader.hpp"
#include "common/errors.hpp"
#include "sampling/obj_loader.hpp"
#include "sampling/outline.hpp"

namespace mw {

namespace {
namespace fs = std::filesystem;

// The run's scene, as summary.json keeps it resolved.
Scene run_scene(const std::string& run_dir) {
    const std::string path = run_dir + "/summary.json";
    std::ifstream in(path);
    if (!in) throw InputError(path + " is missing: RUN_DIR must be a directory that `meltwater run` wrote");
    std::stringstream text;
    text << in.rdbuf();
    SceneJson summary;
    try {
        summary = parse_json_refusing_duplicates(text.str(), path);
    } catch (const SceneJson::exception& e) {
        std::string what = e.what();  // "[json.exception.parse_error.101] parse error at ..."
        const std::size_t bracket = what.find("] ");
        throw InputError(path + ": malformed JSON: " + (bracket == std::string::npos ? what : what.substr(bracket + 2)));
    }
    if (!summary.is_object() || !summary.contains("scene"))
        throw InputError(path + " holds no \"scene\": not a summary `meltwater run` wrote");
    return resolve_scene(summary["scene"], path + " (its scene)");
}

// frame number -> simulated time, from particles.pvd ("" file: none known).
std::map<int, double> frame_times(const std::string& frames_dir) {
    std::map<int, double> times;
    std::ifstream in(frames_dir + "/particles.pvd");
    std::string line;
    while (std::getline(in, line)) {
        const std::size_t t = line.find("timestep=\""), f = line.find("file=\"particles_");
        if (t == std::string::npos || f == std::string::npos) continue;
        const int number = frame_file_number(line.substr(f + 6, line.find('"', f + 6) - (f + 6)));
        if (number >= 0) times[number] = std::strtod(line.c_str() + t + 10, nullptr);
    }
    return times;
}

// The frame's particles back in the form a run hands the preview.
HostParticles frame_particles(const std::string& path) {
    const VtuFrame frame = read_vtu(path);
    const std::size_t n = frame.points.size();
    HostParticles p;
    p.position = frame.points;
    p.velocity.assign(n, Vec3{0, 0, 0});
    p.density.assign(n, 0);
    p.pressure.assign(n, 0);
    p.type.assign(n, kFluid);
    p.object.assign(n, -1);
    const auto floats = [&](const char* name, std::size_t components) -> const std::vector<float>* {
        const VtuArray* a = frame.find(name);
        return a && a->floats.size() == n * components ? &a->floats : nullptr;
    };
    if (const auto* v = floats("velocity", 3))
        for (std::size_t i = 0; i < n; ++i) p.velocity[i] = Vec3{(*v)[3 * i], (*v)[3 * i + 1], (*v)[3 * i + 2]};
    if (const auto* d = floats("density", 1)) p.density.assign(d->begin(), d->end());
    if (const auto* q = floats("pressure", 1)) p.pressure.assign(q->begin(), q->end());
    if (const auto* t = floats("temperature", 1)) p.temperature.assign(t->begin(), t->end());
    if (const VtuArray* type = frame.find("type"); type && type->bytes.size() == n) p.type = type->bytes;
    if (const VtuArray* object = frame.find("object"); object && object->ints.size() == n) p.object = object->ints;
    return p;
}

// A frame's OBJ as the run wrote it: faces (a solid's mesh or the fluid's surface), one line (a
// rod), or one "l a b" per edge (a 2D object's outline or the 2D fluid's contour, read back as an
// outline, sampling/outline.hpp).
TriangleMesh load_frame_obj(const std::string& path) {
    std::ifstream in(path);
    if (!in) throw InputError(path + ": cannot be read");
    int edges = 0, vertices = 0;
    for (std::string line; std::getline(in, line);) {
        if (line.rfind("f ", 0) == 0) return load_obj(path, false);
        edges += line.rfind("l ", 0) == 0;
        vertices += line.rfind("v ", 0) == 0;
    }
    // A frame without fluid writes a surface with no vertex: nothing to draw.
    if (vertices == 0) return TriangleMesh{};
    return edges < 2 ? load_obj(path, false) : load_obj_edges(path);
}

// The meshes written with frame `number`: each object's, then the fluid's surface. A rod's OBJ is
// its line (one "l", no faces), drawn as the run's preview draws it: a tube of `rod_radius`. A 2D
// object's outline is not drawn (its particles show it); the 2D fluid's contour is, as a band
// `contour_width` wide.
std::vector<PreviewMesh> frame_meshes(const std::string& frames_dir, int number, double rod_radius, double contour_width) {
    std::vector<PreviewMesh> meshes;
    std::vector<std::string> objects;
    for (const auto& entry : fs::directory_iterator(frames_dir)) {
        const std::string name = entry.path().filename().string();
        if (name.rfind("object_", 0) == 0 && frame_file_number(name) == number) objects.push_back(name);
    }
    std::sort(objects.begin(), objects.end());
    const auto vertices_of = [](const TriangleMesh& m) {
        std::vector<std::array<double, 3>> v(m.vertices.size());
        for (std::size_t k = 0; k < v.size(); ++k) v[k] = {m.vertices[k].x(), m.vertices[k].y(), m.vertices[k].z()};
        return v;
    };
    for (const std::string& name : objects) {
        const TriangleMesh m = load_frame_obj(frames_dir + "/" + name);
        if (is_outline(m)) continue;
        if (m.triangles.empty() && m.vertices.size() > 1)
            meshes.push_back(rod_tube(vertices_of(m), rod_radius));
        else
            meshes.push_back(solid_preview_mesh(vertices_of(m), m.triangles));
    }
    char surface[40];
    std::snprintf(surface, sizeof surface, "/surface_%05d.obj", number);
    if (fs::exists(frames_dir + surface))
        meshes.push_back(surface_preview_mesh(load_frame_obj(frames_dir + surface), contour_width));
    return meshes;
}

// The top of the speed colour bar, the same for every frame: a fall through the domain plus the
// fastest particle of the first frame (the run's own scale, speed_limit.hpp, from what is on disk).
double speed_scale(const Scene& scene, const HostParticles& first) {
    double start = 0;
    for (const Vec3& v : first.velocity) start = std::max(start, double(norm(v)));
    return fall_speed(scene) + start;
}

cxxopts::Options render_options() {
    cxxopts::Options options("meltwater render",
                             "Draws the frames of a run in RUN_DIR (frames/particles_NNNNN.vtu, with the objects' and\n"
                             "the surface's meshes of the same frame) as frames/preview_NNNNN.png, with the camera\n"
                             "and colour field of the run's scene (output.preview) unless given here.");
    options.add_options()("run_dir", "the run's output directory", cxxopts::value<std::string>())(
        "frame", "only this frame number", cxxopts::value<std::string>(), "N")(
        "field", "colour the fluid by speed, pressure, density or temperature", cxxopts::value<std::string>(), "NAME")(
        "width", "picture width, pixels (16 to 8192)", cxxopts::value<std::string>(), "W")(
        "height", "picture height, pixels (16 to 8192)", cxxopts::value<std::string>(), "H")(
        "out", "directory for the pictures (default RUN_DIR/frames)", cxxopts::value<std::string>(), "DIR")(
        "q,quiet", "print nothing but errors")("h,help", "show this help");
    options.parse_positional({"run_dir"});
    options.positional_help("RUN_DIR");
    return options;
}

// The scene's output.preview with the options' changes.
void apply_options(const cxxopts::ParseResult& args, Scene& scene) {
    if (args.count("field")) {
        const std::string f = args["field"].as<std::string>();
        const std::map<std::string, PreviewField> fields{{"speed", PreviewField::kSpeed},
                                                         {"pressure", PreviewField::kPressure},
                                                         {"density", PreviewField::kDensity},
                                                         {"temperature", PreviewField::kTemperature}};
        if (!fields.count(f)) throw InputError("--field must be speed, pressure, density or temperature, got '" + f + "'");
        scene.preview.field = fields.at(f);
    }
    for (const char* side : {"width", "height"}) {
        if (!args.count(side)) continue;
        const long pixels = integer_option(args, side, 0);
        if (pixels < 16 || pixels > 8192) throw InputError(std::string("--") + side + " must be 16 to 8192 pixels");
        (std::string(side) == "width" ? scene.preview.width : scene.preview.height) = int(pixels);
    }
}
}  // namespace

int command_render(int argc, char** argv) {
    cxxopts::Options options = render_options();
    const cxxopts::ParseResult args = parse_options(options, argc, argv);
    if (flag_option(args, "help")) {
        std::printf("%s\n", options.help().c_str());
        return 0;
    }
    if (!args.count("run_dir")) throw InputError("render: missing RUN_DIR (a directory that `meltwater run` wrote)");
    const std::string run_dir = args["run_dir"].as<std::string>();
    if (!fs::is_directory(run_dir)) throw InputError(run_dir + " is not a directory");
    Scene scene = run_scene(run_dir);
    apply_options(args, scene);
    const std::string frames_dir = run_dir + "/frames";
    std::vector<int> numbers;
    std::error_code ec;
    if (fs::is_directory(frames_dir, ec))
        for (const auto& entry : fs::directory_iterator(frames_dir)) {
            const std::string name = entry.path().filename().string();
            if (name.rfind("particles_", 0) == 0 && name.size() > 4 && name.substr(name.size() - 4) == ".vtu" &&
                frame_file_number(name) >= 0)
                numbers.push_back(frame_file_number(name));
        }
    std::sort(numbers.begin(), numbers.end());
    if (numbers.empty())
        throw InputError(frames_dir + " holds no particle frames (particles_NNNNN.vtu): the run needs output.formats \"vtu\"");
    // The speed scale from the run's first frame, whichever frames are drawn.
    char first_name[40];
    std::snprintf(first_name, sizeof first_name, "/particles_%05d.vtu", numbers.front());
    const std::string first_frame = frames_dir + first_name;
    if (args.count("frame")) {
        const long wanted = integer_option(args, "frame", -1);
        if (!std::binary_search(numbers.begin(), numbers.end(), int(wanted)))
            throw InputError("--frame " + std::to_string(wanted) + ": no such frame in " + frames_dir + " (frames " +
                             std::to_string(numbers.front()) + " to " + std::to_string(numbers.back()) + ")");
        numbers = {int(wanted)};
    }
    if (scene.preview.field == PreviewField::kTemperature && !scene.params.heat.enabled)
        throw InputError("--field temperature: the run had no heat conduction (heat.enabled false)");
    const std::string out_dir = args.count("out") ? args["out"].as<std::string>() : frames_dir;
    make_directories(out_dir);
    const std::map<int, double> times = frame_times(frames_dir);
    const double scale = speed_scale(scene, frame_particles(first_frame));
    // The running count only where a person watches (a terminal), not into a log.
    const double rod_radius = 0.5 * double(scene.params.fluid.spacing);
    const bool quiet = flag_option(args, "quiet");
    const bool counting = !quiet && isatty(fileno(stderr));
    std::string last;
    for (std::size_t k = 0; k < numbers.size(); ++k) {
        const int number = numbers[k];
        char name[40];
        std::snprintf(name, sizeof name, "/particles_%05d.vtu", number);
        const HostParticles particles = frame_particles(frames_dir + name);
        const double time = times.count(number) ? times.at(number) : number / scene.fps;
        const Image picture = preview_picture(scene, particles, frame_meshes(frames_dir, number, rod_radius, kContourWidthInR0 * double(scene.params.fluid.spacing)), time,
                                              number, scale);
        std::snprintf(name, sizeof name, "/preview_%05d.png", number);
        last = out_dir + name;
        const std::string png = encode_png(picture);
        write_file_atomically(last, [&](std::ostream& out) { out.write(png.data(), std::streamsize(png.size())); });
        if (counting) std::fprintf(stderr, "\rmeltwater: rendered %zu of %zu pictures", k + 1, numbers.size());
    }
    if (counting) std::fprintf(stderr, "\n");
    if (!quiet)
        std::printf("meltwater: %s in %s (the last: %s)\n", count_of(long(numbers.size()), "picture").c_str(),
                    out_dir.c_str(), last.c_str());
    return 0;
}

}  // namespace mw
