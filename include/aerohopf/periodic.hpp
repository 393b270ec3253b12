#pragma once
// Umbrella header of the periodic layer: limit cycles by harmonic balance, their continuation in
// amplitude from a Hopf point and their Floquet exponents by Hill's method.
#include "periodic/harmonic_balance.hpp"
