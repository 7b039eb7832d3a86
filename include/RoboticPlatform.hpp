#pragma once
// @file RoboticPlatform.hpp
// The paper's header: `#include "RoboticPlatform.hpp"` gives a program all of the Robotic
// Platform with its names usable unqualified (`Transform`, `Vector<6>`, `xRotation`, ...), as the
// paper's example programs use them. New code may include `rp/RoboticPlatform.hpp` and write
// `rp::` instead.

#include "rp/RoboticPlatform.hpp"

using namespace rp;  // NOLINT: the paper's programs use the platform's names unqualified
