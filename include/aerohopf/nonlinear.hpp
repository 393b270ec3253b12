#pragma once
// Umbrella header of the nonlinear layer.
#include "nonlinear/check_jacobian.hpp"
#include "nonlinear/newton.hpp"
#include "nonlinear/system.hpp"
