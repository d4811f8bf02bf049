// A Newton system restricted to the nodes its step moves, solved directly: its lower triangle
// as a scalar sparse matrix (3 rows per active node), factored H = P^T L D L^T P by Eigen's
// SimplicialLDLT with an approximate minimum degree ordering P. The ordering and the symbolic
// factorisation depend on the sparsity pattern only, so they are kept and reused while the
// model (its build id) and the active set stay the same (every Newton iteration and every step
// of a body whose step moves all its free nodes); only the numeric factorisation is redone.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <cstdint>
#include <span>
#include <vector>

namespace conform::membrane {

class DirectSystem {
 public:
  /// The Hessian's block pattern and blocks as ActiveSystem::Pattern has them; build_id
  /// identifies the model whose pattern they are (Model::build_id, 0: never reuse).
  struct Pattern {
    std::span<const std::int32_t> block_start, block_column, diagonal_block;
    std::span<const Eigen::Matrix3d> blocks;
    std::span<const std::int32_t> active_list;
    std::span<const std::uint8_t> active;
    std::uint64_t build_id = 0;
  };
  /// Copies the active rows' blocks into the sparse matrix and factors it; false if the
  /// factorisation failed (a matrix not positive definite to working precision).
  bool factor(const Pattern& pattern);
  /// step = H^-1 b (3 x #active, in the active list's order).
  void solve(const Eigen::Matrix3Xd& b, Eigen::Matrix3Xd& step) const;
  /// How many times the ordering and symbolic factorisation were computed (for tests).
  int analyses() const { return analyses_; }

 private:
  bool same_pattern(const Pattern& pattern) const;
  void build_pattern(const Pattern& pattern);

  std::uint64_t build_id_ = 0;
  std::vector<std::int32_t> active_list_;   // the active set the pattern was built for
  std::vector<std::int32_t> local_;         // per vertex: its index among the active, or -1
  std::vector<std::int32_t> source_;        // per stored 3 x 3 block: its index in blocks
  std::vector<std::int32_t> source_start_;  // per active row: its first in source_
  Eigen::SparseMatrix<double> lower_;       // column-major, the lower triangle
  Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Eigen::AMDOrdering<int>> ldlt_;
  int analyses_ = 0;
  mutable Eigen::VectorXd rhs_, x_;
};

}  // namespace conform::membrane
