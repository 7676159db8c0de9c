// meltwater.Simulation: a scene simulated on either backend, stepped with the interpreter's lock
// released; each step's report as a dict, the particles as NumPy arrays, frames and stats.csv.
#include <cmath>
#include <cstdio>
#include <optional>
#include <stdexcept>

#include <pybind11/stl.h>

#include "apps/fluid_inside_objects.hpp"
#include "common/errors.hpp"
#include "python/bindings.hpp"
#include "python/particle_arrays.hpp"
#include "python/simulation_handle.hpp"

namespace mw::python {

namespace {
// The Python object: the simulation, and whether a call is using it with the lock released; a
// call from another thread meanwhile would race it.
struct PySimulation {
    std::unique_ptr<SimulationHandle> h;
    bool busy = false;
};

class InUse {
   public:
    explicit InUse(PySimulation& s) : s_(s) {
        if (s_.busy) throw std::runtime_error("the simulation is in use by another thread's call");
        s_.busy = true;
    }
    ~InUse() { s_.busy = false; }
    InUse(const InUse&) = delete;
    InUse& operator=(const InUse&) = delete;

   private:
    PySimulation& s_;
};

// The simulation for a call that reads it: refused while another thread's call steps it (its
// report and counts change under the reader).
const SimulationHandle& idle(const PySimulation& s) {
    if (s.busy) throw std::runtime_error("the simulation is in use by another thread's call");
    return *s.h;
}

// A step's report as stats.csv has it: the fluid's figures, the modules' columns by name (heat:
// heat_substeps, heat_content; melting: melted; emitters: emitted), and each stage's time.
py::dict report_dict(const StepReport& r, const std::vector<std::string>& stages) {
    py::dict d;
    d["step"] = r.step;
    d["time"] = r.time;
    d["dt"] = r.dt;
    d["iterations"] = r.iterations;
    d["density_error_avg"] = r.density_error_avg;
    d["density_error_max"] = r.density_error_max;
    d["max_speed"] = r.max_speed;
    d["kinetic_energy"] = r.kinetic_energy;
    d["lost_particles"] = r.lost_particles;
    d["solid_kinetic_energy"] = r.solid_kinetic_energy;
    d["solid_max_speed"] = r.solid_max_speed;
    d["retries"] = r.retries;
    d["diverged"] = r.diverged;
    d["unconverged"] = r.unconverged;
    for (std::size_t k = 0; k < r.column_names.size() && k < r.columns.size(); ++k)
        d[py::str(r.column_names[k])] = r.columns[k];
    py::dict ms;
    for (std::size_t k = 0; k < stages.size() && k < r.stage_ms.size(); ++k) ms[py::str(stages[k])] = r.stage_ms[k];
    d["stage_ms"] = ms;
    d["total_ms"] = r.total_ms;
    return d;
}

py::dict last_report(const PySimulation& s) {
    const SimulationHandle& h = idle(s);
    return report_dict(h.last_report(), h.simulation().stage_names());
}

py::dict counts_dict(const ParticleCounts& c) {
    py::dict d;
    for (int t = 0; t < kParticleTypeCount; ++t) d[particle_type_name(t)] = c.by_type[t];
    d["total"] = c.total();
    return d;
}

std::string path_text(const py::handle& path, const char* what) {
    const py::object text = py::module_::import("os").attr("fspath")(path);
    if (!py::isinstance<py::str>(text)) throw py::type_error(std::string(what) + ": a path must be text, not bytes");
    return text.cast<std::string>();
}

// Where run() stops: after `steps` steps, or at the step that reaches `until` (to a relative
// 1e-9, so that 0.1 + 0.1 + ... counts), or at run.end_time, as `meltwater run` does.
struct RunEnd {
    long steps = 0;  // 0: run to `time`
    double time = 0;
};

RunEnd run_end(const SimulationHandle& h, const std::optional<long>& steps, const std::optional<double>& until) {
    if (steps && until) throw InputError("steps and until exclude each other; give one");
    RunEnd end;
    if (steps) {
        if (*steps < 1) throw InputError("steps must be at least 1, got " + std::to_string(*steps));
        end.steps = *steps;
        return end;
    }
    end.time = until ? *until : h.scene().scene.end_time;
    // The CLI's bound on --time: 1e300 s would run for ever.
    if (until && !(end.time > 0 && end.time <= 1e6))
        throw InputError("until must be in (0, 1e6] seconds, got " + py::repr(py::float_(end.time)).cast<std::string>());
    return end;
}

py::dict run(PySimulation& s, const std::optional<long>& steps, const std::optional<double>& until,
             const py::object& frames) {
    const RunEnd end = run_end(*s.h, steps, until);
    const InUse use(s);
    SimulationHandle& h = *s.h;
    FrameSeries* series = frames.is_none() ? nullptr : &h.frames(path_text(frames, "frames"));
    {
        py::gil_scoped_release nogil;
        if (series && series->written() == 0) h.write_frame(*series);  // the state the run starts from
    }
    for (long done = 0; end.steps > 0 ? done < end.steps : h.simulation().time() < end.time * (1 - 1e-9); ++done) {
        {
            py::gil_scoped_release nogil;
            const StepReport& r = h.step();
            if (series && series->due(r.time)) h.write_frame(*series);
        }
        // Ctrl-C stops the run after a whole step: KeyboardInterrupt, the simulation intact.
        if (PyErr_CheckSignals() != 0) throw py::error_already_set();
    }
    return report_dict(h.last_report(), h.simulation().stage_names());
}

Snapshot snapshot_of(PySimulation& s) {
    const InUse use(s);
    py::gil_scoped_release nogil;
    return s.h->particles();
}

template <class T>
py::object field(PySimulation& s, const std::vector<T> HostParticles::*member) {
    const Snapshot snapshot = snapshot_of(s);
    if ((*snapshot.*member).empty() && !snapshot->type.empty()) return py::none();  // temperature without heat
    return scalar_array(snapshot, member);
}

py::array forces_array(const std::vector<std::array<double, 3>>& forces) {
    py::array_t<double> a({static_cast<py::ssize_t>(forces.size()), py::ssize_t(3)});
    auto w = a.mutable_unchecked<2>();
    for (std::size_t i = 0; i < forces.size(); ++i)
        for (int k = 0; k < 3; ++k) w(py::ssize_t(i), k) = forces[i][k];
    return a;
}

std::unique_ptr<PySimulation> make_simulation(const py::object& scene, const std::string& backend, int threads,
                                              bool guards) {
    SceneHandle source =
        py::isinstance<SceneHandle>(scene) ? scene.cast<SceneHandle>() : scene_from_python(scene, py::none());
    auto s = std::make_unique<PySimulation>();
    {
        py::gil_scoped_release nogil;
        s->h = std::make_unique<SimulationHandle>(std::move(source), backend, threads, guards);
    }
    for (const std::string& w : s->h->warnings())
        if (PyErr_WarnEx(PyExc_RuntimeWarning, w.c_str(), 1) < 0) throw py::error_already_set();
    return s;
}

void bind_fields(py::class_<PySimulation>& c) {
    c.def_property_readonly(
         "position", [](PySimulation& s) { return vec3_array(snapshot_of(s), &HostParticles::position); },
         "N x 3 positions, m, in the scene's order (read-only; float32, float64 in a double build).")
        .def_property_readonly(
            "velocity", [](PySimulation& s) { return vec3_array(snapshot_of(s), &HostParticles::velocity); },
            "N x 3 velocities, m/s.")
        .def_property_readonly("density", [](PySimulation& s) { return field(s, &HostParticles::density); },
                               "N densities, kg/m^3.")
        .def_property_readonly("pressure", [](PySimulation& s) { return field(s, &HostParticles::pressure); },
                               "N pressures, Pa.")
        .def_property_readonly("type", [](PySimulation& s) { return field(s, &HostParticles::type); },
                               "N type codes, uint8 (meltwater.FLUID, STATIC_BOUNDARY, ...).")
        .def_property_readonly("object", [](PySimulation& s) { return field(s, &HostParticles::object); },
                               "N body indices, int32: the scene's objects, then its static boxes; -1 for "
                               "fluid and walls.")
        .def_property_readonly("temperature", [](PySimulation& s) { return field(s, &HostParticles::temperature); },
                               "N temperatures, C, with heat conduction (heat.enabled); None without.")
        .def("fields", [](PySimulation& s) { return all_arrays(snapshot_of(s)); },
             "Every field above by name, from one download (temperature only with heat).");
}

void bind_outputs(py::class_<PySimulation>& c) {
    c.def(
         "write_frame",
         [](PySimulation& s, const py::object& directory) {
             const InUse use(s);
             FrameSeries& series = s.h->frames(path_text(directory, "write_frame"));
             py::gil_scoped_release nogil;
             return s.h->write_frame(series);
         },
         py::arg("directory"),
         "Writes the state now as DIRECTORY/particles_NNNNN.vtu (numbered from 0 for each directory) and "
         "rewrites DIRECTORY/particles.pvd, the collection ParaView opens. Returns the frame's path.")
        .def(
            "write_stats",
            [](PySimulation& s, const py::object& path) {
                const std::string p = path_text(path, "write_stats");
                const InUse use(s);
                py::gil_scoped_release nogil;
                s.h->write_stats(p);
            },
            py::arg("path"), "Writes stats.csv of the steps so far, as `meltwater run` writes it.");
}

void bind_state(py::class_<PySimulation>& c) {
    c.def_property_readonly("last_report", &last_report, "The last step's report (step 0 before the first).")
        .def_property_readonly("time", [](const PySimulation& s) { return idle(s).simulation().time(); },
                               "Simulated time, s.")
        .def_property_readonly("step_count", [](const PySimulation& s) { return idle(s).last_report().step; },
                               "Steps taken.")
        .def_property_readonly("counts", [](const PySimulation& s) { return counts_dict(idle(s).simulation().counts()); },
                               "Particles by type name (fluid, static_boundary, sbp, ibp, gp, pending) and total.")
        .def_property_readonly("scene", [](const PySimulation& s) { return idle(s).scene(); })
        .def_property_readonly("backend", [](const PySimulation& s) { return idle(s).simulation().backend_name(); })
        .def_property_readonly("device", [](const PySimulation& s) { return idle(s).simulation().device_name(); })
        .def_property_readonly("threads", [](const PySimulation& s) { return idle(s).threads(); },
                               "The OpenMP threads it was built with (threads=0: the count that meant).")
        .def_property_readonly("stage_names", [](const PySimulation& s) { return idle(s).simulation().stage_names(); },
                               "The stages a step runs, in order (the keys of a report's stage_ms).")
        .def_property_readonly("device_bytes", [](const PySimulation& s) { return idle(s).simulation().device_bytes(); })
        .def_property_readonly("fluid_carved", [](const PySimulation& s) { return idle(s).fluid_carved(); },
                               "Fluid particles left out where static boxes and objects stand.")
        .def_property_readonly("speed_limit", [](const PySimulation& s) { return idle(s).speed_limit(); },
                               "The runaway guard's limit, m/s (0: none).")
        .def_property_readonly("warnings", [](const PySimulation& s) { return idle(s).warnings(); },
                               "The scene's warnings (also issued as RuntimeWarning when built).")
        .def("fluid_force_on_solids",
             [](const PySimulation& s) { return forces_array(idle(s).simulation().fluid_force_on_solids()); },
             "The fluid's force on each solid object in the last step, N, as an array of shape (objects, 3).")
        .def("fluid_inside_objects",
             [](PySimulation& s) { return fluid_inside_outlines(idle(s).solids(), *snapshot_of(s)); },
             "Per object, the fluid particles whose centres lie inside its outline now: the penetrations the "
             "paper's 2D figures draw in red (moving 2D objects; -1 for any other object).")
        .def("__repr__", [](const PySimulation& s) {
            if (s.busy) return std::string("<meltwater.Simulation, stepping in another thread>");
            const SimulationHandle& h = *s.h;
            char time[32];
            std::snprintf(time, sizeof time, "%.6g", h.simulation().time());
            return "<meltwater.Simulation " + h.scene().scene.name + " on " + h.backend() + ", " +
                   std::to_string(h.simulation().counts().total()) + " particles, step " +
                   std::to_string(h.last_report().step) + ", t = " + time + " s>";
        });
}
}  // namespace

void bind_simulation(py::module_& m) {
    py::class_<PySimulation> c(m, "Simulation", R"(A scene simulated as `meltwater run` simulates it.

Simulation(scene=None, backend="auto", threads=0, guards=True)

scene: a Scene, or anything Scene() takes (None: the built-in dam break; a path; a dict).
backend: "auto" (CUDA where a GPU is usable, else OpenMP), "cuda" or "openmp". "cuda" without a
usable GPU raises meltwater.DeviceError.
threads: OpenMP threads for the set-up and the openmp backend, 1 to 1024; 0 for all cores.
guards: stop with meltwater.SimulationError at the step that loses more than
boundary.max_lost_fraction of the fluid, passes solver.max_density_error or solver.max_speed
(docs/running.md), as the CLI does.)");
    c.def(py::init(&make_simulation), py::arg("scene") = py::none(), py::arg("backend") = "auto",
          py::arg("threads") = 0, py::arg("guards") = true)
        .def(
            "step",
            [](PySimulation& s) {
                {
                    const InUse use(s);
                    py::gil_scoped_release nogil;
                    s.h->step();
                }
                return last_report(s);
            },
            "Takes one step; returns its report.")
        .def("run", &run, py::arg("steps") = py::none(), py::arg("until") = py::none(), py::arg("frames") = py::none(),
             R"(Steps on; returns the last step's report.

steps: exactly this many steps. until: simulated time T, s: stops at the step that reaches it (a
step is not shortened to land on it; no step when the simulation is already there). Neither: to
the scene's run.end_time. frames: a directory to write frames into at the scene's output.fps, as
write_frame() does (the first at the start, when the directory has none of this simulation's yet).
Ctrl-C stops after the current step with KeyboardInterrupt.)");
    bind_state(c);
    bind_fields(c);
    bind_outputs(c);
}

}  // namespace mw::python
