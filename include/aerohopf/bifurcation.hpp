#pragma once
// Umbrella header of the bifurcation layer.
#include "bifurcation/cayley.hpp"
#include "bifurcation/continuation.hpp"
#include "bifurcation/equilibrium_krylov.hpp"
#include "bifurcation/hopf.hpp"
#include "bifurcation/hopf_bordered.hpp"
#include "bifurcation/hopf_curve.hpp"
#include "bifurcation/hopf_curve_fixed_equilibrium.hpp"
#include "bifurcation/hopf_point.hpp"
#include "bifurcation/inverse_power.hpp"
#include "bifurcation/root_locus.hpp"
#include "bifurcation/vg_diagram.hpp"
