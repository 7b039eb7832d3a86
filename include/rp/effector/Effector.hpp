#pragma once
/// @file
/// The end-effector classes (paper section 3.4): grippers, force/torque sensors, tool changers, and the simulated work piece.

#include "rp/effector/AtiFTSensor.hpp"
#include "rp/effector/BarrettHand.hpp"
#include "rp/effector/DefaultGripper.hpp"
#include "rp/effector/DefaultToolChanger.hpp"
#include "rp/effector/ForceTorqueSensor.hpp"
#include "rp/effector/Gripper.hpp"
#include "rp/effector/ToolChanger.hpp"
#include "rp/effector/WorkPiece.hpp"
