#include <Eigen/Dense>

#include "solve_context.hpp"

namespace conform::membrane::solver_detail {
namespace {

// Phase 5a: each changed element's six distinct Hessian blocks (a <= b) at x, into upper_
// (parallel over the elements; the element's full state is rebuilt here, not kept).
void element_hessians(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  Solver::Scratch& s = c.s;
  const auto nc = static_cast<std::int64_t>(s.changed_.size());
  s.upper_.resize(std::size_t(6 * nc));
#pragma omp parallel for schedule(static) num_threads(c.threads) if (c.parallel())
  for (std::int64_t k = 0; k < nc; ++k) {
    const std::int32_t e = s.changed_[std::size_t(k)];
    detail::ElementState state = state_at(c, e, x);
    detail::add_hessian_terms(state);
    detail::hessian_upper_blocks(c.model.elements()[std::size_t(e)], state, c.model.lambda(),
                                 c.model.mu(), &s.upper_[std::size_t(6 * k)]);
  }
}

constexpr int kPair[3][3] = {{0, 1, 2}, {1, 3, 4}, {2, 4, 5}};  // (a, b) -> upper_ index

// Adds corner a's row of an element's blocks (its six upper ones, hessian_upper_blocks) to the
// blocks of the element's row block a.
void add_element_row(Context& c, std::int64_t e, int a, const Eigen::Matrix3d* upper) {
  const auto& element_block = c.model.element_block();
  for (int b = 0; b < 3; ++b) {
    Eigen::Matrix3d& block =
        c.s.blocks_[std::size_t(element_block[std::size_t(9 * e + 3 * a + b)])];
    if (a <= b)
      block += upper[kPair[a][b]];
    else
      block += upper[kPair[a][b]].transpose();
  }
}

// The nodal attachment and inertia terms on row v's diagonal block, and its inverse.
void finish_diagonal(Context& c, std::int32_t v) {
  Solver::Scratch& s = c.s;
  Eigen::Matrix3d& k = s.blocks_[std::size_t(c.model.diagonal_block()[std::size_t(v)])];
  k += s.node_stiffness_[std::size_t(v)];
  if (c.dynamic) k.diagonal().array() += s.inertia_weight_[v];
  k.diagonal().array() += 1e-12 * k.trace() + 1e-300;  // a lone node stays invertible
  s.block_inverse_[std::size_t(v)] = k.inverse();
}

// Phase 5b in parallel: each active row's blocks gathered from its elements' blocks (all
// changed, as it is active; element_hessians) in ascending element order, so that the sums do
// not depend on the thread count.
void gather_hessians(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  Solver::Scratch& s = c.s;
  element_hessians(c, x);
  const auto& row_start = c.model.block_start();
  const auto& start = c.model.incidence_start();
  const auto& inc = c.model.incidence();
  const auto na = static_cast<std::int64_t>(s.active_list_.size());
#pragma omp parallel for schedule(static) num_threads(c.threads) if (c.parallel())
  for (std::int64_t i = 0; i < na; ++i) {
    const std::int32_t v = s.active_list_[std::size_t(i)];
    for (std::int32_t j = row_start[std::size_t(v)]; j < row_start[std::size_t(v) + 1]; ++j)
      s.blocks_[std::size_t(j)].setZero();
    for (std::int32_t k = start[std::size_t(v)]; k < start[std::size_t(v) + 1]; ++k) {
      const std::int32_t e = inc[std::size_t(k)] / 3, a = inc[std::size_t(k)] % 3;
      add_element_row(c, e, a, &s.upper_[std::size_t(6 * s.changed_slot_[std::size_t(e)])]);
    }
    finish_diagonal(c, v);
  }
}

// Phase 5b serially: the changed elements in ascending order, each one's blocks computed and
// added straight to its active corners' rows. Every block receives the same terms in the same
// (ascending element) order as in gather_hessians, so the sums are the same bit for bit,
// without the round trip of every element's blocks through memory.
void scatter_hessians(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  Solver::Scratch& s = c.s;
  const auto& row_start = c.model.block_start();
  for (const std::int32_t v : s.active_list_)
    for (std::int32_t j = row_start[std::size_t(v)]; j < row_start[std::size_t(v) + 1]; ++j)
      s.blocks_[std::size_t(j)].setZero();
  Eigen::Matrix3d upper[6];
  for (std::int64_t e = 0; e < c.ne; ++e) {
    if (s.changed_slot_[std::size_t(e)] < 0) continue;
    detail::ElementState state = state_at(c, e, x);
    detail::add_hessian_terms(state);
    detail::hessian_upper_blocks(c.model.elements()[std::size_t(e)], state, c.model.lambda(),
                                 c.model.mu(), upper);
    const mesh::Face& f = c.model.element_faces()[std::size_t(e)];
    for (int a = 0; a < 3; ++a)
      if (s.active_[std::size_t(f[std::size_t(a)])]) add_element_row(c, e, a, upper);
  }
  for (const std::int32_t v : s.active_list_) finish_diagonal(c, v);
}

}  // namespace

// Phase 5b: the Hessian approximation's 3 x 3 blocks of the active rows, with the nodal
// attachment and inertia terms on the diagonal, and the diagonal blocks' inverses (both
// preconditioners use them). Blocks of inactive rows are neither written nor read.
void assemble(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  Solver::Scratch& s = c.s;
  s.blocks_.resize(c.model.block_column().size());
  s.block_inverse_.resize(static_cast<std::size_t>(c.nv));
  if (c.parallel())
    gather_hessians(c, x);
  else
    scatter_hessians(c, x);
}

}  // namespace conform::membrane::solver_detail
