// Fuzz target: an isolated import's result as its caller receives it, bytes from a child that
// may have been corrupted (core/internal/conform/io/model_wire.hpp, then model_check.hpp).
// Properties, for any bytes:
//   - decode_model throws std::runtime_error, or returns a model that encodes to the same bytes;
//   - check_model refuses it, or the model is safe to use as the commands use it: its mesh
//     check, pieces, adjacency, skinning of the rest pose, an animation sample and the weld run
//     without reading out of bounds (ASan and UBSan in the fuzz build; the replay in the normal
//     suite runs the same code).
#include <cstdint>
#include <stdexcept>
#include <string_view>

#include "conform/io/model_check.hpp"
#include "conform/io/model_wire.hpp"
#include "conform/io/weld_model.hpp"
#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/skin/pose.hpp"
#include "conform/skin/skinner.hpp"
#include "fuzz_bytes.hpp"

using namespace conform;

namespace {

void use_model(io::SkinnedModel& model) {
  (void)mesh::check_mesh(model.mesh);
  (void)mesh::label_pieces(model.mesh);
  const mesh::Adjacency adjacency(model.mesh);
  skin::Skinner<double> skinner(model.skeleton, model.mesh.rest, model.influences);
  skinner.skin(skin::Pose::rest(model.skeleton), skin::SkinMode::cga);
  skinner.write(model.mesh.current);
  for (const auto& animation : model.animations) {
    skin::Pose pose;
    animation.sample(model.skeleton, 0.5 * animation.duration(), skin::Blend::linear, pose);
    fuzz::fuzz_require(pose.local.size() == model.skeleton.joints.size(),
                       "an animation sample has another joint count");
  }
  (void)io::weld_model(model);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  io::SkinnedModel model;
  try {
    model = io::decode_model(bytes);
  } catch (const std::runtime_error&) {
    return 0;  // refused: the caller's ImportError
  }
  fuzz::fuzz_require(io::encode_model(model) == bytes, "a decoded model encodes to other bytes");
  if (!io::check_model(model).empty()) return 0;
  use_model(model);
  return 0;
}
