// The skin as a membrane: its material (laws, pre-stress, direction field, attachment), the
// model built on a mesh and its implicit solver. Everything in one include.
#pragma once

#include "conform/membrane/model.hpp"
#include "conform/membrane/skin_material.hpp"
#include "conform/membrane/solver.hpp"
