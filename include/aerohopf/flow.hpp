#pragma once
// Umbrella header of the flow layer: structured multi-block grids, metrics, the NACA C-grid
// generator, the dimension-generic ALE Euler residual (Osher / MUSCL / van Albada), exact and
// modified-order Jacobians, and the pseudo-transient steady solver.
#include "flow/euler_model.hpp"
#include "flow/gas.hpp"
#include "flow/jacobian.hpp"
#include "flow/metrics.hpp"
#include "flow/muscl.hpp"
#include "flow/naca_cgrid.hpp"
#include "flow/osher_flux.hpp"
#include "flow/steady_solver.hpp"
#include "flow/structured_grid.hpp"
