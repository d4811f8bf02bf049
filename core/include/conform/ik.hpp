// The closed-form CGA inverse kinematics of a two-segment arm, scalar and batched, with its
// joint limits. Everything in one include.
#pragma once

#include "conform/ik/arm_ik.hpp"
#include "conform/ik/limits.hpp"
