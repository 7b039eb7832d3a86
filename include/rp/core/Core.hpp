#pragma once
/// @file
/// The core classes: objects, object manager, type database, configuration and platform start-up.

#include "rp/core/ClassSection.hpp"
#include "rp/core/Configuration.hpp"
#include "rp/core/FunctionalObject.hpp"
#include "rp/core/ObjectManager.hpp"
#include "rp/core/PhysicalObject.hpp"
#include "rp/core/RoboticObject.hpp"
#include "rp/core/RoboticPlatform.hpp"
#include "rp/core/TypeDatabase.hpp"
