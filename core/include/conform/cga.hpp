// Conformal geometric algebra G(4,1): everything in one include.
#pragma once

#include "conform/cga/blades.hpp"
#include "conform/cga/motor.hpp"
#include "conform/cga/multivector.hpp"
#include "conform/cga/plane.hpp"
#include "conform/cga/point.hpp"
#include "conform/cga/rounds_flats.hpp"
#include "conform/cga/sphere.hpp"
#include "conform/cga/versor.hpp"
