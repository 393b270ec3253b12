#pragma once
// Umbrella header of the reduction layer: derivative products (finite differences in any
// precision, exact taylor jets) and the centre-manifold reduction with its 2-DOF model.
#include "reduction/centre_manifold.hpp"
#include "reduction/derivative_products.hpp"
