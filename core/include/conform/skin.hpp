// CGA skinning: skeletons, poses, animations and the skinner that blends motors (dilations
// included), with the procedural arm. Everything in one include.
#pragma once

#include "conform/skin/animation.hpp"
#include "conform/skin/pose.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "conform/skin/skeleton.hpp"
#include "conform/skin/skinner.hpp"
#include "conform/skin/skinning.hpp"
