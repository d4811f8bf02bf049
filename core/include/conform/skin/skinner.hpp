// A ready-to-use skinning pipeline for one mesh and skeleton: owns the SoA buffers (rest
// positions, K influences, per-bone versors/kernels, output) so that posing a frame — the
// hierarchy walk, the per-bone coefficients and the vertex loop — allocates nothing.
#pragma once

#include <optional>
#include <string_view>

#include "conform/skin/baselines.hpp"
#include "conform/skin/pose.hpp"
#include "conform/skin/skinning.hpp"

namespace conform::skin {

enum class SkinMode {
  cga,              // eq 17, per-term down-projection (the project's skinning path)
  versor,           // blend the versors, apply one
  matrix_lbs,       // baseline: Eigen 4×4 matrix LBS
  dual_quaternion,  // baseline: dual-quaternion skinning
};

/// "lbs"/"cga" → cga, "versor", "matrix", "dq"; empty on anything else.
std::optional<SkinMode> parse_skin_mode(std::string_view text);
const char* skin_mode_name(SkinMode mode);

template <class T = double>
class Skinner {
 public:
  /// `skeleton` must outlive the skinner. Uses each vertex's `max_influences` largest
  /// influences, renormalized. Throws std::invalid_argument on inconsistent sizes or bone ids.
  Skinner(const Skeleton& skeleton, Eigen::Ref<const Eigen::Matrix3Xd> rest,
          const InfluenceLists& influences, int max_influences = mesh::kMaxInfluences);
  /// The same with influences already in the jobs' layout, used as they are (e.g.
  /// Influences::from_mesh, a mesh's own weights without renormalization).
  Skinner(const Skeleton& skeleton, Eigen::Ref<const Eigen::Matrix3Xd> rest,
          Influences<T> influences);

  /// New rest points and influences for the same skeleton (a mesh that gained vertices); the
  /// per-bone buffers stay. Throws std::invalid_argument, changing nothing, on inconsistent
  /// sizes or bone ids.
  void set_points(Eigen::Ref<const Eigen::Matrix3Xd> rest, Influences<T> influences);

  /// Poses the mesh: per-bone coefficients for `mode` from `pose`, then the vertex loop.
  void skin(const Pose& pose, SkinMode mode);
  /// The same into `out` (resized to vertex_count()) instead of output(): a caller that keeps
  /// the previous frame swaps two buffers instead of copying one.
  void skin(const Pose& pose, SkinMode mode, SoaPoints<T>& out);
  /// Per-bone step only (what skin() does before the vertex loop).
  void prepare(const Pose& pose, SkinMode mode);
  /// Vertex loop only, with the coefficients of the last prepare().
  void run(SkinMode mode);

  void set_threads(int threads) { threads_ = threads; }
  const SoaPoints<T>& output() const { return out_; }
  /// Writes the skinned points (into an Eigen::Matrix3Xd or a mesh's ColumnArray).
  template <class Columns>
  void write(Columns& points) const {
    out_.to(points);
  }
  std::span<const Versor> skinning_versors() const { return skin_versors_; }
  const Influences<T>& influences() const { return influences_; }
  std::size_t vertex_count() const { return rest_.size(); }

 private:
  SkinInput<T> input() const;
  SkinOutput<T> output_span();
  void run(SkinMode mode, SkinOutput<T> out);

  const Skeleton* skeleton_;
  SoaPoints<T> rest_, out_;
  Influences<T> influences_;
  std::vector<Versor> global_, skin_versors_;
  std::vector<Kernel34<T>> kernels_;
  std::vector<VersorCoefficients<T>> coefficients_;
  std::vector<DqBone<T>> dq_;
  MatrixRig matrices_;
  int threads_ = 0;
};

}  // namespace conform::skin
