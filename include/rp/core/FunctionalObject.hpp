#pragma once
/// @file
/// FunctionalObject (paper section 3.2), declared next to PhysicalObject.

#include "rp/core/PhysicalObject.hpp"
