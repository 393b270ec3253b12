#pragma once
// Umbrella header of the io layer: Plot3D grids, VTK flow fields.
#include "io/plot3d.hpp"
#include "io/vtk.hpp"
