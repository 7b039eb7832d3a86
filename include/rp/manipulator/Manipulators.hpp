#pragma once
/// @file
/// Manipulators, their servo controls and their simulation.

#include "rp/control/DefaultPositionControl.hpp"
#include "rp/control/ServoControl.hpp"
#include "rp/manipulator/BarrettArm.hpp"
#include "rp/manipulator/DefaultManipulator.hpp"
#include "rp/manipulator/Manipulator.hpp"
#include "rp/manipulator/ManipulatorSimulation.hpp"
#include "rp/manipulator/Puma560.hpp"
#include "rp/manipulator/UrdfManipulator.hpp"
#include "rp/manipulator/WAM.hpp"
#include "rp/trajectory/DefaultTrajectoryGenerator.hpp"
#include "rp/trajectory/JerkLimitedProfile.hpp"
#include "rp/trajectory/OfflinePlanner.hpp"
#include "rp/trajectory/QueueTrajectoryGenerator.hpp"
#include "rp/trajectory/SynchronizedJointMotion.hpp"
#include "rp/trajectory/Synchronization.hpp"
#include "rp/trajectory/TimedJointTrajectory.hpp"
#include "rp/trajectory/TimedTrajectoryGenerator.hpp"
#include "rp/trajectory/TrajectoryGenerator.hpp"
