#include "python/particle_arrays.hpp"

#include <type_traits>

namespace mw::python {

namespace {
static_assert(sizeof(Vec3) == 3 * sizeof(Real) && std::is_standard_layout_v<Vec3>,
              "a Vec3 array is viewed as N x 3 Reals");

// A capsule that holds a reference to the snapshot: the array's base, so the snapshot lives as
// long as any array that views it.
py::capsule owner_of(const Snapshot& snapshot) {
    return py::capsule(new Snapshot(snapshot), [](void* p) { delete static_cast<Snapshot*>(p); });
}

py::array read_only(py::array a) {
    a.attr("flags").attr("writeable") = false;
    return a;
}
}  // namespace

py::array vec3_array(const Snapshot& snapshot, const std::vector<Vec3> HostParticles::*field) {
    const std::vector<Vec3>& v = (*snapshot).*field;
    const py::ssize_t n = static_cast<py::ssize_t>(v.size());
    return read_only(py::array_t<Real>({n, py::ssize_t(3)}, {py::ssize_t(sizeof(Vec3)), py::ssize_t(sizeof(Real))},
                                       v.empty() ? nullptr : &v[0].x, owner_of(snapshot)));
}

template <class T>
py::array scalar_array(const Snapshot& snapshot, const std::vector<T> HostParticles::*field) {
    const std::vector<T>& v = (*snapshot).*field;
    return read_only(py::array_t<T>({static_cast<py::ssize_t>(v.size())}, {py::ssize_t(sizeof(T))},
                                    v.empty() ? nullptr : v.data(), owner_of(snapshot)));
}

template py::array scalar_array<Real>(const Snapshot&, const std::vector<Real> HostParticles::*);
template py::array scalar_array<std::uint8_t>(const Snapshot&, const std::vector<std::uint8_t> HostParticles::*);
template py::array scalar_array<std::int32_t>(const Snapshot&, const std::vector<std::int32_t> HostParticles::*);

py::dict all_arrays(const Snapshot& s) {
    py::dict d;
    d["position"] = vec3_array(s, &HostParticles::position);
    d["velocity"] = vec3_array(s, &HostParticles::velocity);
    d["density"] = scalar_array(s, &HostParticles::density);
    d["pressure"] = scalar_array(s, &HostParticles::pressure);
    d["type"] = scalar_array(s, &HostParticles::type);
    d["object"] = scalar_array(s, &HostParticles::object);
    if (!s->temperature.empty()) d["temperature"] = scalar_array(s, &HostParticles::temperature);
    return d;
}

}  // namespace mw::python
