// The particles of a simulation as NumPy arrays, without a copy past the download: each array
// views the vectors of one downloaded snapshot and keeps that snapshot alive. Arrays are
// read-only (writing to them could not reach the simulation, so it is refused rather than lost);
// .copy() gives one to change. The next step downloads a new snapshot: arrays taken before it keep
// the values they had.
#pragma once
#include <memory>

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include "simulation/simulation.hpp"

namespace mw::python {
namespace py = pybind11;

using Snapshot = std::shared_ptr<const HostParticles>;

// N x 3 positions or velocities, of mw::Real (float32, or float64 in a double build).
py::array vec3_array(const Snapshot& snapshot, const std::vector<Vec3> HostParticles::*field);
// N values of one of the scalar fields (density, pressure, type, object, temperature).
template <class T>
py::array scalar_array(const Snapshot& snapshot, const std::vector<T> HostParticles::*field);

// Every field by name, temperature only with heat conduction.
py::dict all_arrays(const Snapshot& snapshot);

}  // namespace mw::python
