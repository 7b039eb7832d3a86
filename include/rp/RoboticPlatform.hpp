#pragma once
/// @file rp/RoboticPlatform.hpp
/// Umbrella header: everything a Robotic Platform program uses, in namespace `rp`.
///
/// Programs written as in the paper include `"RoboticPlatform.hpp"` instead, which also brings
/// the names into the global namespace.

#include "rp/math/Math.hpp"
#include "rp/core/Core.hpp"
#include "rp/rt/RealTime.hpp"
#include "rp/model/Model.hpp"
#include "rp/manipulator/Manipulators.hpp"
#include "rp/io/Io.hpp"
#include "rp/effector/Effector.hpp"
#include "rp/gui/SceneViewer.hpp"
#include "rp/ros2/RemoteManipulator.hpp"
#include "rp/ros2/Ros2Bridge.hpp"
