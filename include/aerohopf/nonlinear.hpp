#pragma once
// Umbrella header of the nonlinear layer.
#include "nonlinear/newton.hpp"
#include "nonlinear/system.hpp"
