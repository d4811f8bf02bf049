// The Bullet plugin: skinned soft bodies driven by CGA skinning, their cuts, tears, drills and
// released pieces, a rigid-body scalpel and the conversions between Conform and Bullet.
// Everything an application uses, in one include; link conform::bullet.
#pragma once

#include "conform/bullet/convert.hpp"
#include "conform/bullet/non_finite_state.hpp"
#include "conform/bullet/piece.hpp"
#include "conform/bullet/plugin.hpp"
#include "conform/bullet/rigid_scalpel.hpp"
#include "conform/bullet/skinned_soft_body.hpp"
#include "conform/bullet/tear_growth.hpp"
