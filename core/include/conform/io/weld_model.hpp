// Welding an imported model (mesh/weld.hpp): each mesh of the file on its own, with the model's
// influence lists and mesh ranges following the new vertex and face numbering.
#pragma once

#include "conform/io/model.hpp"
#include "conform/mesh/weld.hpp"

namespace conform::io {

/// Welds `model.mesh` mesh by mesh (a vertex outside every MeshInfo range welds only with
/// others outside them), renumbers `model.influences` and `model.meshes`, and records a warning
/// when vertices at one position were kept apart because their weights differ. Call it before
/// `current` is needed elsewhere: it keeps each kept vertex's own current position.
mesh::WeldResult weld_model(SkinnedModel& model, const mesh::WeldOptions& options = {});

}  // namespace conform::io
