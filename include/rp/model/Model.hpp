#pragma once
/// @file
/// Manipulator models and their kinematics and dynamics algorithms.

#include "rp/model/Dynamics.hpp"
#include "rp/model/InverseKinematics.hpp"
#include "rp/model/Kinematics.hpp"
#include "rp/model/ManipulatorData.hpp"
#include "rp/model/ManipulatorModel.hpp"
#include "rp/model/MjcfExport.hpp"
#include "rp/model/PhysicalModel.hpp"
#include "rp/model/Puma560Model.hpp"
#include "rp/model/UrdfExport.hpp"
#include "rp/model/UrdfModel.hpp"
#include "rp/model/WAMModel.hpp"
