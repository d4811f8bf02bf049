#include "direct_system.hpp"

#include <algorithm>

namespace conform::membrane {

bool DirectSystem::same_pattern(const Pattern& m) const {
  return m.build_id != 0 && m.build_id == build_id_ && lower_.rows() > 0 &&
         std::equal(m.active_list.begin(), m.active_list.end(), active_list_.begin(),
                    active_list_.end());
}

// Column 3 i + a of the lower triangle is row 3 i + a of the upper one (H is symmetric): row
// i's diagonal block from its row a down, then its blocks in active columns right of the
// diagonal, ascending (the model's block columns are ascending within a row, and so are the
// local indices of ascending vertices).
void DirectSystem::build_pattern(const Pattern& m) {
  const std::size_t n = m.active_list.size();
  local_.assign(m.active.size(), -1);
  for (std::size_t i = 0; i < n; ++i) local_[std::size_t(m.active_list[i])] = std::int32_t(i);
  active_list_.assign(m.active_list.begin(), m.active_list.end());
  build_id_ = m.build_id;
  source_.clear();
  source_start_.assign(1, 0);
  std::vector<std::int32_t> outer(3 * n + 1, 0), inner;
  std::vector<std::int32_t> row_blocks;
  for (std::size_t i = 0; i < n; ++i) {
    const auto v = std::size_t(m.active_list[i]);
    row_blocks.clear();
    for (std::int32_t j = m.diagonal_block[v]; j < m.block_start[v + 1]; ++j)
      if (local_[std::size_t(m.block_column[std::size_t(j)])] >= 0) row_blocks.push_back(j);
    for (int a = 0; a < 3; ++a) {
      for (const std::int32_t j : row_blocks) {
        const std::int32_t k = local_[std::size_t(m.block_column[std::size_t(j)])];
        for (int b = (k == std::int32_t(i) ? a : 0); b < 3; ++b) inner.push_back(3 * k + b);
      }
      outer[3 * i + std::size_t(a) + 1] = std::int32_t(inner.size());
    }
    source_.insert(source_.end(), row_blocks.begin(), row_blocks.end());
    source_start_.push_back(std::int32_t(source_.size()));
  }
  const auto size = Eigen::Index(3 * n);
  lower_.resize(size, size);
  lower_.resizeNonZeros(Eigen::Index(inner.size()));
  std::copy(outer.begin(), outer.end(), lower_.outerIndexPtr());
  std::copy(inner.begin(), inner.end(), lower_.innerIndexPtr());
}

bool DirectSystem::factor(const Pattern& m) {
  const bool reuse = same_pattern(m);
  if (!reuse) build_pattern(m);
  // The values, in the order build_pattern laid the entries out.
  double* value = lower_.valuePtr();
  const std::size_t n = m.active_list.size();
  for (std::size_t i = 0; i < n; ++i) {
    const auto first = std::size_t(source_start_[i]), end = std::size_t(source_start_[i + 1]);
    for (int a = 0; a < 3; ++a)
      for (std::size_t s = first; s < end; ++s) {
        const Eigen::Matrix3d& h = m.blocks[std::size_t(source_[s])];
        for (int b = (s == first ? a : 0); b < 3; ++b) *value++ = h(a, b);
      }
  }
  if (!reuse) {
    ldlt_.analyzePattern(lower_);
    ++analyses_;
  }
  ldlt_.factorize(lower_);
  return ldlt_.info() == Eigen::Success;
}

void DirectSystem::solve(const Eigen::Matrix3Xd& b, Eigen::Matrix3Xd& step) const {
  rhs_ = Eigen::Map<const Eigen::VectorXd>(b.data(), b.size());
  x_ = ldlt_.solve(rhs_);
  step.resize(3, b.cols());
  Eigen::Map<Eigen::VectorXd>(step.data(), step.size()) = x_;
}

}  // namespace conform::membrane
