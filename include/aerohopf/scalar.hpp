#pragma once
// Umbrella header of the scalar layer.
#include "scalar/complex.hpp"
#include "scalar/jet.hpp"
#include "scalar/qd.hpp"
#include "scalar/taylor.hpp"
#include "scalar/traits.hpp"
