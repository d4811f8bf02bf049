// The skin as a membrane, as an application sets it: its material (laws, pre-stress, direction
// field, attachment, toughness) and its solver's settings and report. The model, the solver
// and the fracture mechanics behind them are the library's own (core/internal). One include.
#pragma once

#include "conform/membrane/skin_material.hpp"
#include "conform/membrane/solver_settings.hpp"
