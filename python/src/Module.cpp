// The Python module `roboticplatform` (import roboticplatform as rp): the library's exceptions
// as Python exceptions, then the models and the platform.
#include <pybind11/pybind11.h>

#include "Bindings.hpp"
#include "ResultBuffers.hpp"
#include "rp/core/Configuration.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/io/IoException.hpp"
#include "rp/math/MathException.hpp"

PYBIND11_MODULE(_roboticplatform, m) {
  namespace py = pybind11;
  m.doc() = "Robotic Platform: models, trajectories and manipulators of the C++ library, with numpy arrays.";
  py::register_exception<rp::ConfigError>(m, "ConfigError", PyExc_ValueError).doc() =
      "A malformed rp.cfg or setting: the file and line and what is wrong.";
  py::register_exception<rp::ObjectError>(m, "ObjectError", PyExc_RuntimeError).doc() =
      "An object that cannot be created or used (e.g. no rp.cfg section of that name).";
  py::register_exception<rp::MathException>(m, "MathError", PyExc_ValueError).doc() =
      "A math error of the library (e.g. a singular matrix).";
  py::register_exception<rp::IoException>(m, "IoError", PyExc_OSError).doc() =
      "A failed input or output of a device or hardware server.";
  rp::python::bindModels(m);
  rp::python::bindPlatform(m);
  rp::python::bindTrajectories(m);
  m.def("_kept_result_bytes", &rp::python::keptResultBytes,
        "Bytes now kept in freed result buffers of the batched calls, for the next large result (tests).");
}
