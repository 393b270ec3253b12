#pragma once
// Umbrella header of the nonlinear layer.
#include "nonlinear/aeroelastic_system.hpp"
#include "nonlinear/block_system.hpp"
#include "nonlinear/check_jacobian.hpp"
#include "nonlinear/newton.hpp"
#include "nonlinear/system.hpp"
