// The geometric copy of a tear, beside a physical one: the same scalpel samples on the mesh
// alone (no physics), opened by Algorithm 2 step 6 (Tear::open) once the stroke is done. On a
// still mesh (tear-opening's posed arm) it is torn where it stands; on an animated model
// (character) repose() skins it anew to the skeleton's pose before every sample and measure,
// and opens it again, so the copy follows the animation and nothing else.
#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <optional>

#include "conform/mesh/tear.hpp"
#include "conform/skin/pose.hpp"
#include "conform/skin/skeleton.hpp"
#include "conform/skin/skinner.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {

class GeometricTear {
 public:
  /// Tears `mesh` as its `current` positions stand (with the lips of `options`).
  GeometricTear(mesh::SkinnedMesh mesh, const mesh::TearOptions& options);
  GeometricTear(const GeometricTear&) = delete;
  GeometricTear& operator=(const GeometricTear&) = delete;

  /// One scalpel sample, the same one the physical tear gets.
  mesh::TearStep advance(const mesh::ScalpelSample& sample) { return tear_.advance(sample); }
  /// Step 6: the borders moved apart by `amount` (metres, sine taper) from now on.
  void open(double amount);
  bool opened() const { return amount_.has_value(); }
  /// Poses the mesh anew: CGA skinning of its rest positions with `pose`, placed by `world`,
  /// then the opening (when opened) applied again. The mesh's new vertices (the tear's) are
  /// skinned with the weights the tear gave them.
  void repose(const skin::Skeleton& skeleton, const skin::Pose& pose,
              const Eigen::Isometry3d& world);
  /// The gap-width profile along the tear now (empty before it has two points).
  Profile profile() const;

  const mesh::SkinnedMesh& mesh() const { return mesh_; }
  const mesh::Tear& tear() const { return tear_; }

 private:
  mesh::SkinnedMesh mesh_;
  mesh::Adjacency adjacency_;
  mesh::Tear tear_;
  std::optional<double> amount_;
  std::unique_ptr<skin::Skinner<double>> skinner_;  // built on the first repose()
  std::int32_t skinned_vertices_ = 0;               // the vertex count the skinner has
};

}  // namespace conform::scenes
