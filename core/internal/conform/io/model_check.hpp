// The structural check of a SkinnedModel that the caller of an isolated import makes on the
// child's result (model_wire.hpp only checks that the bytes are one whole encoding): every
// array has the size its counts imply, every index is in range, every number finite, the
// skeleton, the influences and the animations valid. A model that passes can be welded,
// skinned, cut, torn, drilled and simulated without reading out of bounds; one from a child
// whose memory assimp corrupted is refused instead of used.
#pragma once

#include <string>

#include "conform/io/model.hpp"

namespace conform::io {

/// Empty when `model` is well formed, else its first problem ("mesh face 7 has vertex 90 of 12").
std::string check_model(const SkinnedModel& model);

}  // namespace conform::io
