// Skinning jobs (data-oriented, ozz style): plain structs of spans, validate() then run().
// Jobs own no buffers and allocate nothing; OpenMP splits the vertex loop.
//
// Layout (structure of arrays, #V vertices, K influence slots per vertex):
//   x, y, z           #V each      rest positions
//   bones, weights    K · #V each  slot k of vertex v at [k · #V + v]; weights sorted
//                                  decreasing per vertex, summing to 1, unused slots weight 0
//   out x, y, z       #V each      posed positions
// Because weights are sorted, a vertex's loop stops at its first zero weight.
//
// Bone influences have three representations, each where it is needed:
//   mesh::SkinnedMesh::bones/weights  4 per vertex, one column each: what apply() blends into
//                                     a new vertex (§4.3) and a cut, tear or drill carries;
//   InfluenceLists                    any number per vertex, as imported: the source from
//                                     which a Skinner's K largest are chosen;
//   Influences<T>                     the jobs' K-slot SoA layout, made by select() (from
//                                     lists, renormalized) or from_mesh() (a mesh's as stored).
//
// Modes:
//   CgaSkinningJob     eq 17 with per-term down-projection (§4.3): each term
//                      down(V_n c V_n⁻¹) = d_n R_n x + t_n is a 3×4 kernel (A_n = d_n R_n,
//                      b_n = t_n) computed once per bone per frame from the versor
//                      V_n = M_n,k B_n; per vertex C = Σ w_n (A_n x + b_n).
//   VersorBlendJob     blends the versors first, V = normalize(Σ ±w_n M_n) with dilation
//                      d = Σ w_n d_n, and applies the one versor (dual-quaternion-like: no
//                      candy-wrapper collapse).
// The baselines (matrix LBS, dual quaternions) are in baselines.hpp.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "conform/mesh/skinned_mesh.hpp"
#include "conform/skin/skeleton.hpp"

namespace conform::skin {

/// Every influence of every vertex as imported, any number per vertex (compressed rows).
struct InfluenceLists {
  std::vector<std::int32_t> offsets{0};  // #V + 1; vertex v has [offsets[v], offsets[v + 1])
  std::vector<std::int32_t> bones;
  std::vector<double> weights;

  std::int32_t vertex_count() const { return static_cast<std::int32_t>(offsets.size()) - 1; }
  /// The largest number of non-zero influences of one vertex.
  int max_per_vertex() const;
  /// The (up to 4) influences stored in a SkinnedMesh.
  static InfluenceLists from_mesh(const mesh::SkinnedMesh& mesh);
  /// Empty when every bone id is in [0, bone_count), every weight finite and ≥ 0, and every
  /// vertex's weights sum to 1 within `tolerance`; else the first problem.
  std::string validate(std::int32_t bone_count, double tolerance = 1e-3) const;
};

/// SoA influences, K slots per vertex (see the layout above).
template <class T>
struct Influences {
  std::int32_t vertex_count = 0;
  int count = 0;  // K
  std::vector<std::int32_t> bones;
  std::vector<T> weights;

  /// Each vertex's `k` largest influences, renormalized to sum 1 (a vertex with no influence
  /// gets bone 0 at weight 1). Ties keep the imported order.
  static Influences select(const InfluenceLists& lists, int k = mesh::kMaxInfluences);
  /// The mesh's kMaxInfluences slots exactly as stored (the mesh keeps them sorted and summing
  /// to 1, skinned_mesh.hpp): no selection and no renormalization, so skinning them gives the
  /// same bits as the mesh's own weights.
  static Influences from_mesh(const mesh::SkinnedMesh& mesh);
};

template <class T>
struct SoaPoints {
  std::vector<T> x, y, z;

  static SoaPoints from(Eigen::Ref<const Eigen::Matrix3Xd> points);
  void resize(std::size_t n) { x.resize(n), y.resize(n), z.resize(n); }
  std::size_t size() const { return x.size(); }
  /// Writes the points into a 3 × n matrix (an Eigen::Matrix3Xd or a mesh's ColumnArray,
  /// resized if needed).
  template <class Columns>
  void to(Columns& points) const {
    const auto n = static_cast<Eigen::Index>(x.size());
    if (points.cols() != n) points.resize(3, n);
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto u = static_cast<std::size_t>(i);
      points(0, i) = x[u], points(1, i) = y[u], points(2, i) = z[u];
    }
  }
};

/// Row-major 3×4 [A | b]: x' = A x + b.
template <class T>
struct alignas(32) Kernel34 {
  T m[12];
};

/// The 9 coefficients a versor-blend needs per bone: the motor's 8 and the dilation.
template <class T>
struct VersorCoefficients {
  T s, e12, e13, e23, e1inf, e2inf, e3inf, e123inf, scale;
};

/// Kernels of the skinning versors, once per bone per frame: A = d R, b = t (versor.hpp).
template <class T>
void versor_kernels(std::span<const Versor> versors, std::span<Kernel34<T>> out);
template <class T>
void versor_coefficients(std::span<const Versor> versors, std::span<VersorCoefficients<T>> out);

template <class T>
struct SkinInput {
  std::span<const T> x, y, z;
  int influences = 0;  // K
  std::span<const std::int32_t> bones;
  std::span<const T> weights;
};

template <class T>
struct SkinOutput {
  std::span<T> x, y, z;
};

/// Empty when the spans have consistent sizes and every used bone id indexes a bone of
/// `bone_count`; else the problem.
template <class T>
std::string validate_skin_io(const SkinInput<T>& in, const SkinOutput<T>& out,
                             std::size_t bone_count);

/// OpenMP thread count used by the jobs: `threads` if > 0, else the OpenMP default; 1 for
/// meshes under 1024 vertices, where forking costs more than it saves.
int skin_threads(int threads, std::size_t vertex_count);

template <class T>
struct CgaSkinningJob {
  std::span<const Kernel34<T>> kernels;  // one per bone: down-projected M_n,k B_n
  SkinInput<T> input;
  SkinOutput<T> output;
  int threads = 0;

  std::string validate() const { return validate_skin_io(input, output, kernels.size()); }
  void run() const;
};

template <class T>
struct VersorBlendJob {
  std::span<const VersorCoefficients<T>> versors;  // one per bone: M_n,k B_n
  SkinInput<T> input;
  SkinOutput<T> output;
  int threads = 0;

  std::string validate() const { return validate_skin_io(input, output, versors.size()); }
  void run() const;
};

/// Eq 17 for one point by the general G(4,1) product: Σ_n w_n down(V_n up(x) V_n⁻¹). Slow; the
/// reference the kernels are tested against.
Eigen::Vector3d skin_point_by_sandwich(std::span<const Versor> versors,
                                       std::span<const std::int32_t> bones,
                                       std::span<const double> weights, const Eigen::Vector3d& x);

}  // namespace conform::skin
