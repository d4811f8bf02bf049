// A Newton system restricted to the nodes its step moves, packed: the active rows in the
// active list's order, each with its diagonal block, that block's inverse and its blocks in
// active columns below and above the diagonal (columns as local indices), and every vector as
// 3 x #active. The symmetric Gauss-Seidel conjugate gradients then read contiguous memory
// instead of the whole mesh's block rows with a test per column. The operations and their order
// are those of the solve over the mesh's arrays, so the step is the same bit for bit.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <vector>

namespace conform::membrane {

class ActiveSystem {
 public:
  /// The Hessian's 3 x 3 block pattern (Model::block_start, block_column, diagonal_block), its
  /// blocks (blocks[j] of pattern entry j), the inverses of the diagonal blocks per vertex, and
  /// the active vertices (ascending) with their per-vertex mark.
  struct Pattern {
    std::span<const std::int32_t> block_start, block_column, diagonal_block;
    std::span<const Eigen::Matrix3d> blocks, block_inverse;
    std::span<const std::int32_t> active_list;
    std::span<const std::uint8_t> active;
  };
  void pack(const Pattern& pattern);

  /// Solves H step = b (b and step 3 x #active, in the active list's order) by conjugate
  /// gradients preconditioned by symmetric Gauss-Seidel (Eisenstat's trick), until the
  /// transformed residual falls below relative_tolerance of its start; returns the iterations.
  int gauss_seidel_cg(const Eigen::Matrix3Xd& b, double relative_tolerance, int max_iterations,
                      Eigen::Matrix3Xd& step);

 private:
  // out = l^-1 rhs (forward) or l^-T rhs (backward), l = D + L; out may be rhs.
  void lower_solve(const Eigen::Matrix3Xd& rhs, Eigen::Matrix3Xd& out, bool forward) const;

  std::vector<std::int32_t> local_;  // per vertex: its index among the active, or -1
  std::vector<std::int32_t> lower_start_, lower_column_, upper_start_, upper_column_;
  std::vector<Eigen::Matrix3d> lower_, upper_, diagonal_, inverse_;
  Eigen::Matrix3Xd r_, z_, p_, q_, t_, y_;
};

}  // namespace conform::membrane
