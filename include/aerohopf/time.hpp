#pragma once
// Umbrella header of the time layer: fixed-step RK4 and implicit BDF2 (with dual time) for
// verification runs against the reduced models, and the growth-rate check of an eigenvalue.
#include "time/bdf2.hpp"
#include "time/eigenmode_march.hpp"
#include "time/history.hpp"
#include "time/runge_kutta.hpp"
