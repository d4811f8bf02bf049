#include "active_system.hpp"

#include <cmath>

namespace conform::membrane {

void ActiveSystem::pack(const Pattern& m) {
  const std::size_t n = m.active_list.size();
  local_.assign(m.active.size(), -1);
  for (std::size_t i = 0; i < n; ++i) local_[std::size_t(m.active_list[i])] = std::int32_t(i);
  lower_start_.assign(1, 0);
  upper_start_.assign(1, 0);
  lower_column_.clear(), upper_column_.clear(), lower_.clear(), upper_.clear();
  diagonal_.resize(n);
  inverse_.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    const auto v = std::size_t(m.active_list[i]);
    const std::int32_t diagonal = m.diagonal_block[v];
    for (std::int32_t j = m.block_start[v]; j < m.block_start[v + 1]; ++j) {
      const std::int32_t u = local_[std::size_t(m.block_column[std::size_t(j)])];
      if (u < 0 || j == diagonal) continue;
      (j < diagonal ? lower_column_ : upper_column_).push_back(u);
      (j < diagonal ? lower_ : upper_).push_back(m.blocks[std::size_t(j)]);
    }
    lower_start_.push_back(std::int32_t(lower_column_.size()));
    upper_start_.push_back(std::int32_t(upper_column_.size()));
    diagonal_[i] = m.blocks[std::size_t(diagonal)];
    inverse_[i] = m.block_inverse[v];
  }
}

void ActiveSystem::lower_solve(const Eigen::Matrix3Xd& rhs, Eigen::Matrix3Xd& out,
                               bool forward) const {
  const auto n = static_cast<std::int64_t>(diagonal_.size());
  const auto& start = forward ? lower_start_ : upper_start_;
  const auto& column = forward ? lower_column_ : upper_column_;
  const auto& block = forward ? lower_ : upper_;
  for (std::int64_t k = 0; k < n; ++k) {
    const std::int64_t i = forward ? k : n - 1 - k;
    Eigen::Vector3d sum = rhs.col(i);
    for (std::int32_t j = start[std::size_t(i)]; j < start[std::size_t(i) + 1]; ++j)
      sum.noalias() -= block[std::size_t(j)] * out.col(column[std::size_t(j)]);
    out.col(i) = inverse_[std::size_t(i)] * sum;
  }
}

// CG on l^-1 H l^-T y = l^-1 b with the preconditioner D, step = l^-T y, where
// l^-1 H l^-T p = t + l^-1 (p - D t), t = l^-T p: one forward and one backward sweep.
int ActiveSystem::gauss_seidel_cg(const Eigen::Matrix3Xd& b, double relative_tolerance,
                                  int max_iterations, Eigen::Matrix3Xd& step) {
  const auto n = static_cast<Eigen::Index>(diagonal_.size());
  for (auto* v : {&r_, &z_, &p_, &q_, &t_, &y_}) v->resize(3, n);
  step.resize(3, n);
  lower_solve(b, r_, true);  // r = l^-1 b
  double rz = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    y_.col(i).setZero();
    z_.col(i) = diagonal_[std::size_t(i)] * r_.col(i);
    p_.col(i) = z_.col(i);
    rz += r_.col(i).dot(z_.col(i));
  }
  const double stop = relative_tolerance * std::sqrt(rz);
  int it = 0;
  while (it < max_iterations && std::sqrt(rz) > stop) {
    lower_solve(p_, t_, false);  // t = l^-T p
    for (Eigen::Index i = 0; i < n; ++i) q_.col(i) = p_.col(i) - diagonal_[std::size_t(i)] * t_.col(i);
    lower_solve(q_, q_, true);  // in place: row i reads only rows before it
    double pq = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      q_.col(i) += t_.col(i);
      pq += p_.col(i).dot(q_.col(i));
    }
    if (!(pq > 0)) break;
    const double alpha = rz / pq;
    double rz_next = 0;
    for (Eigen::Index i = 0; i < n; ++i) {
      y_.col(i) += alpha * p_.col(i);
      r_.col(i) -= alpha * q_.col(i);
      z_.col(i) = diagonal_[std::size_t(i)] * r_.col(i);
      rz_next += r_.col(i).dot(z_.col(i));
    }
    const double beta = rz_next / rz;
    for (Eigen::Index i = 0; i < n; ++i) p_.col(i) = z_.col(i) + beta * p_.col(i);
    rz = rz_next;
    ++it;
  }
  lower_solve(y_, step, false);  // step = l^-T y
  return it;
}

}  // namespace conform::membrane
