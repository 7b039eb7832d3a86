#pragma once
/// @file
/// The whole math library: matrices and vectors, transforms, filters, differentiation and integration.

#include "rp/math/Differentiator.hpp"
#include "rp/math/HighpassFilter.hpp"
#include "rp/math/Integrator.hpp"
#include "rp/math/LowpassFilter.hpp"
#include "rp/math/MathException.hpp"
#include "rp/math/Matrix.hpp"
#include "rp/math/Transform.hpp"
