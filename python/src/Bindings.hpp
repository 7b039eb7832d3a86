// The parts of the Python module `roboticplatform`, each bound in its own file.
#pragma once

#include <pybind11/pybind11.h>

#include <memory>
#include <string>

#include "rp/trajectory/Synchronization.hpp"

namespace rp {
class ManipulatorModel;
}

namespace rp::python {

/// A Python `Model` holding a copy of `model`.
pybind11::object makeModelCopy(const ManipulatorModel& model);

/// Models and their algorithms (Models.cpp).
void bindModels(pybind11::module_& m);
/// The platform and manipulators (Platform.cpp).
void bindPlatform(pybind11::module_& m);
/// Joint motions planned and sampled without an arm (Trajectories.cpp).
void bindTrajectories(pybind11::module_& m);
/// The model of a Python Model object (Models.cpp); a TypeError for anything else.
const ManipulatorModel& modelOf(const pybind11::handle& object);
/// The synchronisation mode named "time", "phase" or "none" (Trajectories.cpp); a ValueError
/// naming the three for anything else.
Synchronization synchronizationOf(const std::string& name);
/// The same model, shared (the Python object may go before whoever keeps it).
std::shared_ptr<const ManipulatorModel> sharedModelOf(const pybind11::handle& object);

}  // namespace rp::python
