// The skin as a membrane: its material (laws, pre-stress, direction field, attachment), the
// model built on a mesh and its implicit solver, the energy release rate at a tear's tip and the
// tear's growth by it. Everything in one include.
#pragma once

#include "conform/membrane/crack_extension.hpp"
#include "conform/membrane/crack_growth.hpp"
#include "conform/membrane/energy_release.hpp"
#include "conform/membrane/model.hpp"
#include "conform/membrane/skin_material.hpp"
#include "conform/membrane/solver.hpp"
