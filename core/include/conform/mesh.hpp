// The skinned mesh and the three edits an application makes on it: everything in one include.
// A cut is computed (compute_cut) and applied (apply) as a TopologyChange; the drill and each tear
// step change the mesh and report their TopologyChange. Under Bullet, edit through
// conform/bullet.hpp's SkinnedSoftBody instead, which mirrors each change into the soft body.
#pragma once

#include "conform/mesh/cut.hpp"
#include "conform/mesh/cut_region.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "conform/mesh/tear.hpp"
#include "conform/mesh/topology_change.hpp"
