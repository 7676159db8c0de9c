// What `meltwater run` (and the Python module's frames) write into a frames directory at each
// frame (output.formats), each file atomically:
//   particles_NNNNN.vtu / .ply   the particles that move: fluid released so far, solids' SBPs, IBPs
//                                and GPs, with velocity, density, pressure, type, object, id (the
//                                particle's index in the scene's list, stable over the run) and
//                                temperature with heat ("vtu", "ply")
//   static_boundary.vtu / .ply   the static boundary particles (walls, static boxes and objects),
//                                written once: they never move
//   particles.pvd                ParaView's collection: each frame's particles with the static ones
//   object_NAME_NNNNN.obj        each solid object's mesh (its GPs), with every frame
//   surface_NNNNN.obj / .ply     the fluid's surface ("surface"; .ply as well with "ply")
//   fluid_NNNNN.vdb              the fluid as OpenVDB grids ("vdb"; surface/fluid_grids.hpp)
//   preview_NNNNN.png            a picture of the frame ("preview"; render/preview.hpp)
#pragma once
#include <array>
#include <string>
#include <utility>
#include <vector>

#include "apps/scene.hpp"
#include "render/image.hpp"
#include "sampling/mesh.hpp"
#include "simulation/simulation.hpp"
#include "surface/fluid_surface.hpp"

namespace mw {

// The NNNNN of a numbered frame file that a run writes (particles_NNNNN.vtu, object_A_NNNNN.obj,
// preview_NNNNN.png, ...), or -1 for any other name.
int frame_file_number(const std::string& name);
// Whether `name` is a file a run writes in frames/: a numbered one, the static boundary's or
// particles.pvd.
bool is_frame_file(const std::string& name);

// A solid object's mesh vertices at this frame: a moving object's GPs in `particles` (scene
// order), a static object's rest mesh.
std::vector<std::array<double, 3>> object_vertices(const SolidSetup& object, const HostParticles& particles);

class FrameWriter {
   public:
    // Creates `frames_dir` (a run's OUT/frames) and its parents.
    FrameWriter(const std::string& frames_dir, const FrameFormats& formats);
    // The solid objects whose meshes go with every frame (static ones: their rest mesh).
    // A melting object has no mesh to write (its lattice is all of it): its particles show it.
    void set_objects(const std::vector<SolidSetup>& solids) {
        objects_.clear();
        for (const SolidSetup& o : solids)
            if (!o.melts()) objects_.push_back(o);
    }
    // Writes frame `index` (simulated time `time`): the particles in each format asked for (and
    // the static boundary's file, the first time), the objects' meshes, and rewrites particles.pvd.
    // Returns the path of the frame's particles (its .vtu, else its .ply, else "").
    std::string write(int index, const HostParticles& particles, double time);
    void write_surface(int index, const TriangleMesh& mesh) const;
    // fluid_NNNNN.vdb from the colour field of the frame.
    void write_fluid_grids(int index, const FluidSurfacer::Field& field) const;
    // preview_NNNNN.png; returns its path.
    std::string write_preview(int index, const Image& picture) const;
    // A resumed run in its checkpoint's directory: frames 0 .. frame_times.size() - 1 (those of
    // them still there), which particles.pvd keeps listing before the new ones; rewrites it at once.
    void keep_earlier(const std::vector<double>& frame_times);
    int written() const { return written_; }  // by this run
    const std::string& directory() const { return frames_dir_; }
    const FrameFormats& formats() const { return formats_; }

   private:
    void write_particles(const std::string& stem, const HostParticles& p, const std::vector<std::size_t>& shown,
                         const std::string& comment) const;
    void write_objects(int index, const HostParticles& particles) const;
    void write_collection() const;
    std::string frames_dir_;
    FrameFormats formats_;
    std::vector<SolidSetup> objects_;
    int written_ = 0;
    bool static_written_ = false, has_static_ = false;
    std::vector<std::pair<double, std::string>> collection_;
};

}  // namespace mw
