#include "python/bindings.hpp"

#include "common/errors.hpp"

namespace mw::python {

std::string to_json_text(const py::handle& value, const std::string& what) {
    // json.dumps asks `default` for what it cannot write itself: a NumPy value turns into its
    // plain Python value there (np.float32, np.int64 and arrays are not floats, ints and lists).
    const py::cpp_function plain([](py::handle o) -> py::object {
        if (py::hasattr(o, "tolist")) return o.attr("tolist")();
        throw py::type_error("a " + py::str(py::type::of(o).attr("__name__")).cast<std::string>() +
                             " is not a JSON value");
    });
    try {
        const py::object dumps = py::module_::import("json").attr("dumps");
        return dumps(value, py::arg("allow_nan") = false, py::arg("default") = plain).cast<std::string>();
    } catch (py::error_already_set& e) {
        // The scene reader's messages name where the problem is; json's say only what it is.
        if (!e.matches(PyExc_TypeError) && !e.matches(PyExc_ValueError)) throw;
        throw InputError(what + ": " + py::str(e.value()).cast<std::string>());
    }
}

py::object from_json_text(const std::string& text) { return py::module_::import("json").attr("loads")(text); }

}  // namespace mw::python
