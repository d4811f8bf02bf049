// Rigged models read through assimp (in an isolated process by default) and meshes written out:
// everything in one include. Link conform::io (find_package(Conform COMPONENTS io)).
#pragma once

#include "conform/io/import.hpp"
#include "conform/io/isolation_limits.hpp"
#include "conform/io/mesh_export.hpp"
#include "conform/io/model.hpp"
#include "conform/io/weld_model.hpp"
