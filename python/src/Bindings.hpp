// The parts of the Python module `roboticplatform`, each bound in its own file.
#pragma once

#include <pybind11/pybind11.h>

namespace rp {
class ManipulatorModel;
}

namespace rp::python {

/// A Python `Model` holding a copy of `model`.
pybind11::object makeModelCopy(const ManipulatorModel& model);

/// Models and their algorithms (Models.cpp).
void bindModels(pybind11::module_& m);
/// The platform, manipulators and trajectories (Platform.cpp).
void bindPlatform(pybind11::module_& m);

}  // namespace rp::python
