// `meltwater sample MESH --spacing R --out DIR`: turns a mesh (an OBJ file or a procedural spec
// such as "sphere:radius=0.5") into surface (SBP), inner (IBP) and geometry (GP) particles, writes
// them as VTU files and prints counts, coverage, volumes and timings.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <string>
#include <vector>

#include "algorithms/particle_types.hpp"
#include "apps/atomic_file.hpp"
#include "apps/cli_common.hpp"
#include "apps/commands.hpp"
#include "apps/vtu_writer.hpp"
#include "simulation/factory.hpp"
#include "common/errors.hpp"
#include "sampling/obj_loader.hpp"
#include "sampling/procedural_meshes.hpp"
#include "sampling/solid_sample.hpp"

namespace mw {

namespace {

// "s" or "x,y,z" -> vector (a single number fills all three when allow_scalar).
Vec3d parse_triple(const std::string& option, const std::string& text, bool allow_scalar) {
    std::vector<double> v;
    std::stringstream in(text);
    std::string item;
    while (std::getline(in, item, ',')) {
        char* end = nullptr;
        const double x = std::strtod(item.c_str(), &end);
        if (item.empty() || *end != '\0' || !std::isfinite(x))
            throw InputError("--" + option + ": '" + text + "' is not a number list");
        v.push_back(x);
    }
    if (v.size() == 1 && allow_scalar) return Vec3d(v[0], v[0], v[0]);
    if (v.size() != 3) throw InputError("--" + option + ": expected x,y,z, got '" + text + "'");
    return Vec3d(v[0], v[1], v[2]);
}

// The --out directory for the lifetime of one `sample` call: created (with any missing parents)
// and checked writable on construction. Unless keep() is called, the destructor undoes what the
// call did: it removes the output files once any of them was written (a mix of new and earlier
// files is no result) and the directories it created, so a failed call leaves no partial output.
class OutputDirectory {
public:
    explicit OutputDirectory(const std::string& path) : path_(path), created_(make_directories(path)) {}
    OutputDirectory(const OutputDirectory&) = delete;
    OutputDirectory& operator=(const OutputDirectory&) = delete;
    ~OutputDirectory() {
        if (kept_) return;
        if (written_) {
            std::error_code ignored;
            for (const char* name : kFiles) std::filesystem::remove(path_of(name), ignored);
        }
        remove_created_directories(created_);
    }
    static constexpr const char* kFiles[] = {"sbp.vtu", "ibp.vtu", "gp.vtu"};
    // Path of one of kFiles; asking for it means it is about to be written.
    std::string file(const char* name) {
        written_ = true;
        return path_of(name);
    }
    void keep() { kept_ = true; }

private:
    std::string path_of(const char* name) const { return (std::filesystem::path(path_) / name).string(); }
    std::string path_;
    std::vector<std::string> created_;  // by this call, innermost first
    bool written_ = false;
    bool kept_ = false;
};

std::vector<Vec3> to_vec3(const std::vector<Vec3d>& in) {
    std::vector<Vec3> out(in.size());
    for (std::size_t i = 0; i < in.size(); ++i)
        out[i] = make_vec3(static_cast<Real>(in[i].x()), static_cast<Real>(in[i].y()), static_cast<Real>(in[i].z()));
    return out;
}

VtuArray int32_components(const std::string& name, int components, std::vector<std::int32_t> values) {
    VtuArray a = VtuArray::int32(name, std::move(values));
    a.components = components;
    return a;
}

}  // namespace

int command_sample(int argc, char** argv) {
    cxxopts::Options options("meltwater sample",
                             "Samples a solid into surface (SBP), inner (IBP) and geometry (GP) particles.\n"
                             "MESH is an OBJ file or a procedural mesh: box, hollow_box, sphere, torus, cylinder,\n"
                             "stairs, e.g. \"sphere:radius=0.5,subdivisions=5\" or \"hollow_box:x=1,y=1,z=1,wall=0.1\".");
    options.add_options()
        ("mesh", "OBJ file or procedural mesh spec", cxxopts::value<std::string>())
        ("spacing", "particle spacing r0 (m), required", cxxopts::value<std::string>(), "R")
        ("out", "output directory for sbp.vtu, ibp.vtu, gp.vtu, required", cxxopts::value<std::string>(), "DIR")
        ("support", "kernel support radius h for the GP links (default 2.5 r0)", cxxopts::value<std::string>(), "H")
        ("scale", "scale, one factor or x,y,z (applied first)", cxxopts::value<std::string>(), "S|X,Y,Z")
        ("rotate", "rotation, Euler angles in degrees about x, y, z (applied in that order)", cxxopts::value<std::string>(), "X,Y,Z")
        ("translate", "translation x,y,z (applied last)", cxxopts::value<std::string>(), "X,Y,Z")
        ("directions", "ray line families for inside/outside: 0 auto (3 closed, 13 open), 3, 7 or 13",
         cxxopts::value<std::string>(), "N")
        ("threads", "OpenMP threads, 1 to 1024 (default: OpenMP's, e.g. OMP_NUM_THREADS)", cxxopts::value<std::string>(), "N")
        ("no-coverage", "skip the coverage check")
        ("h,help", "show this help");
    options.parse_positional({"mesh"});
    options.positional_help("MESH");
    const cxxopts::ParseResult args = parse_options(options, argc, argv);
    if (flag_option(args, "help")) {
        std::printf("%s\n", options.help().c_str());
        return 0;
    }
    if (!args.count("mesh")) throw InputError("sample: missing MESH (an OBJ file or a procedural spec such as sphere:radius=0.5)");
    if (!args.count("spacing")) throw InputError("sample: missing --spacing R (the particle spacing r0 in metres)");
    if (!args.count("out")) throw InputError("sample: missing --out DIR");
    const std::string mesh_arg = args["mesh"].as<std::string>();
    const double r0 = number_option(args, "spacing", 0);
    if (!std::isfinite(r0) || r0 <= 0) throw InputError("--spacing must be a positive number");
    const double h = number_option(args, "support", 2.5 * r0);
    // The same range as a scene's fluid.support_radius: a huge h links every GP to every IBP.
    if (!std::isfinite(h) || !(h > r0) || h > 4 * r0)
        throw InputError("--support must be in (spacing, 4 x spacing], got " + format_number(h) + " with spacing " +
                         format_number(r0));
    const long directions = integer_option(args, "directions", 0);
    if (directions != 0 && directions != 3 && directions != 7 && directions != 13)
        throw InputError("--directions must be 0, 3, 7 or 13");
    // Before the output directory is made: see set_host_threads.
    set_host_threads(threads_option(args));
    const std::string out_dir = args["out"].as<std::string>();
    if (out_dir.empty()) throw InputError("--out: empty directory name");

    const auto t_load = std::chrono::steady_clock::now();
    TriangleMesh mesh;
    std::error_code ec;
    if (is_procedural_spec(mesh_arg) && !std::filesystem::exists(mesh_arg, ec))
        mesh = make_procedural_from_spec(mesh_arg);
    else
        mesh = load_obj(mesh_arg);
    MeshTransform transform;
    if (args.count("scale")) transform.scale = parse_triple("scale", args["scale"].as<std::string>(), true);
    if (args.count("rotate")) transform.rotation_deg = parse_triple("rotate", args["rotate"].as<std::string>(), false);
    if (args.count("translate")) transform.translation = parse_triple("translate", args["translate"].as<std::string>(), false);
    if (!transform.is_identity()) apply_transform(mesh, transform);
    const double load_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_load).count();

    // The output directory is made (and checked writable) before sampling, which may take long,
    // and removed again when this call made it and no complete output follows.
    OutputDirectory output(out_dir);
    SampleOptions opt;
    opt.inside.directions = directions;
    opt.measure_coverage = !flag_option(args, "no-coverage");
    const SolidSample s = sample_solid(mesh, r0, h, opt);
    const SampleStats& st = s.stats;
    if (s.ibp.count() == 0) {
        std::ostringstream message;
        message << mesh.source << ": the mesh holds no inner particle at spacing " << r0
                << " (make it larger or decrease --spacing)";
        throw InputError(message.str());
    }

    const auto t_write = std::chrono::steady_clock::now();
    {
        std::vector<VtuArray> arrays;
        arrays.push_back(VtuArray::uint8("type", std::vector<std::uint8_t>(s.sbp.count(), kSurfaceBoundary)));
        arrays.push_back(VtuArray::vector3("normal", to_vec3(s.sbp.normals)));
        arrays.push_back(VtuArray::int32("triangle", std::vector<std::int32_t>(s.sbp.triangles.begin(), s.sbp.triangles.end())));
        arrays.push_back(VtuArray::vector3("barycentric", to_vec3(s.sbp.barycentric)));
        write_vtu(output.file("sbp.vtu"), to_vec3(s.sbp.positions), arrays);
    }
    {
        std::vector<std::int32_t> lattice, neighbours;
        lattice.reserve(3 * s.ibp.count());
        for (const auto& c : s.ibp.lattice) lattice.insert(lattice.end(), c.begin(), c.end());
        for (std::size_t p = 0; p < s.ibp.count(); ++p)
            neighbours.push_back(s.ibp.neighbor_offsets[p + 1] - s.ibp.neighbor_offsets[p]);
        std::vector<VtuArray> arrays;
        arrays.push_back(VtuArray::uint8("type", std::vector<std::uint8_t>(s.ibp.count(), kInnerBoundary)));
        arrays.push_back(int32_components("lattice", 3, std::move(lattice)));
        arrays.push_back(VtuArray::int32("neighbours", std::move(neighbours)));
        write_vtu(output.file("ibp.vtu"), to_vec3(s.ibp.positions), arrays);
    }
    {
        std::vector<std::int32_t> links;
        for (std::size_t g = 0; g < s.gp.count(); ++g) links.push_back(s.gp.offsets[g + 1] - s.gp.offsets[g]);
        std::vector<VtuArray> arrays;
        arrays.push_back(VtuArray::uint8("type", std::vector<std::uint8_t>(s.gp.count(), kGeometry)));
        arrays.push_back(VtuArray::int32("ibp_links", std::move(links)));
        write_vtu(output.file("gp.vtu"), to_vec3(s.gp.positions), arrays);
    }
    const double write_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_write).count();
    output.keep();

    const double ratio = st.mesh_volume > 0 ? st.ibp_volume / st.mesh_volume : 0.0;
    std::printf("mesh        %s: %zu triangles, %s (%zu boundary edges)%s\n", mesh.source.c_str(), st.triangles,
                st.closed ? "closed" : "open", st.boundary_edges, st.flipped ? ", re-oriented outward" : "");
    std::printf("spacing     r0 = %g, h = %g\n", r0, h);
    std::printf("counts      SBP %zu, IBP %zu, GP %zu (the vertices of the mesh refined to %zu triangles, no edge "
                "longer than r0, as an elastic or rigid object's GPs are)\n",
                st.sbp_count, st.ibp_count, st.gp_count, st.geometry_triangles);
    if (opt.measure_coverage)
        std::printf("coverage    largest surface gap %.4g (%.3f r0), mean %.3f r0, %zu random surface probes\n",
                    st.largest_gap, st.largest_gap / r0, st.mean_gap / r0, st.coverage_probes);
    std::printf("volume      IBPs %.6g, mesh %.6g (ratio %.4f)\n", st.ibp_volume, st.mesh_volume, ratio);
    std::printf("inside      %d ray line families, %zu rays, %zu lattice points where directions disagreed, %zu decided "
                "by the winding number\n",
                st.ray_directions, st.rays, st.ambiguous_points, st.refined_points);
    if (st.gps_without_ibp)
        std::printf("warning     %zu GPs have no IBP within h; linked to their nearest IBP\n", st.gps_without_ibp);
    std::printf("time        load %.3f s, prepare %.3f s, IBP %.3f s (Embree build %.3f s), SBP %.3f s, GP %.3f s, "
                "sampling total %.3f s, coverage check %.3f s, write %.3f s\n",
                load_seconds, s.timings.prepare, s.timings.inner, s.timings.embree, s.timings.surface, s.timings.geometry,
                s.timings.total, s.timings.coverage, write_seconds);
    std::printf("output      %s/{sbp,ibp,gp}.vtu\n", out_dir.c_str());
    return 0;
}

}  // namespace mw
