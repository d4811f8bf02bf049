#include <Eigen/Dense>
#include <cmath>

#include "solve_context.hpp"

namespace conform::membrane::solver_detail {
namespace {

// out = H d over the active rows and columns (only active rows of out are written).
void hessian_apply(Context& c, const Eigen::Matrix3Xd& d, Eigen::Matrix3Xd& out) {
  const auto& start = c.model.block_start();
  const auto& column = c.model.block_column();
  const auto& list = c.s.active_list_;
  const auto na = static_cast<std::int64_t>(list.size());
#pragma omp parallel for schedule(static) num_threads(c.threads) if (c.parallel())
  for (std::int64_t i = 0; i < na; ++i) {
    const auto v = std::size_t(list[std::size_t(i)]);
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (std::int32_t j = start[v]; j < start[v + 1]; ++j) {
      const std::int32_t u = column[std::size_t(j)];
      if (c.s.active_[std::size_t(u)]) sum.noalias() += c.s.blocks_[std::size_t(j)] * d.col(u);
    }
    out.col(std::int64_t(v)) = sum;
  }
}

// Phase 6: H step = -g over the active nodes by preconditioned conjugate gradients, on the
// active columns only; returns the iterations.
int jacobi_cg(Context& c) {
  Solver::Scratch& s = c.s;
  const auto& list = s.active_list_;
  double rz = 0, rr = 0;
  for (const std::int32_t v : list) {
    s.step_.col(v).setZero();
    s.r_.col(v) = -s.gradient_.col(v);
    s.z_.col(v) = s.block_inverse_[std::size_t(v)] * s.r_.col(v);
    s.p_.col(v) = s.z_.col(v);
    rz += s.r_.col(v).dot(s.z_.col(v));
    rr += s.r_.col(v).squaredNorm();
  }
  const double stop = c.settings.cg_relative_tolerance * std::sqrt(rr);
  int it = 0;
  while (it < c.settings.max_cg_iterations && std::sqrt(rr) > stop) {
    hessian_apply(c, s.p_, s.q_);
    double pq = 0;
    for (const std::int32_t v : list) pq += s.p_.col(v).dot(s.q_.col(v));
    if (!(pq > 0)) break;  // no curvature left along p (cannot happen with a PSD H unless p = 0)
    const double alpha = rz / pq;
    double rz_next = 0;
    rr = 0;
    for (const std::int32_t v : list) {
      s.step_.col(v) += alpha * s.p_.col(v);
      s.r_.col(v) -= alpha * s.q_.col(v);
      s.z_.col(v) = s.block_inverse_[std::size_t(v)] * s.r_.col(v);
      rz_next += s.r_.col(v).dot(s.z_.col(v));
      rr += s.r_.col(v).squaredNorm();
    }
    const double beta = rz_next / rz;
    for (const std::int32_t v : list) s.p_.col(v) = s.z_.col(v) + beta * s.p_.col(v);
    rz = rz_next;
    ++it;
  }
  return it;
}

// With H = l + l^T - D (l = D + L, L the strictly lower blocks in vertex order, over the active
// rows and columns): out = l^-1 rhs (forward) or l^-T rhs (backward) by block substitution.
void lower_solve(Context& c, const Eigen::Matrix3Xd& rhs, Eigen::Matrix3Xd& out, bool forward) {
  Solver::Scratch& s = c.s;
  const auto& start = c.model.block_start();
  const auto& column = c.model.block_column();
  const auto& diagonal = c.model.diagonal_block();
  const auto n = static_cast<std::int64_t>(s.active_list_.size());
  for (std::int64_t i = 0; i < n; ++i) {
    const auto v = std::size_t(s.active_list_[std::size_t(forward ? i : n - 1 - i)]);
    Eigen::Vector3d sum = rhs.col(std::int64_t(v));
    const std::int32_t first = forward ? start[v] : diagonal[v] + 1;
    const std::int32_t last = forward ? diagonal[v] : start[v + 1];
    for (std::int32_t j = first; j < last; ++j) {
      const std::int32_t u = column[std::size_t(j)];
      if (s.active_[std::size_t(u)]) sum.noalias() -= s.blocks_[std::size_t(j)] * out.col(u);
    }
    out.col(std::int64_t(v)) = s.block_inverse_[v] * sum;
  }
}

// Symmetric Gauss-Seidel preconditioned CG by Eisenstat's trick: CG on the SPD system
// l^-1 H l^-T y = l^-1 b (b = -g, step = l^-T y) with the preconditioner D, where
//   l^-1 H l^-T p = t + l^-1 (p - D t),  t = l^-T p,
// costs one forward and one backward sweep (together one multiplication by H). The stopping
// test is on the transformed residual, relative to its start.
int gauss_seidel_cg(Context& c) {
  Solver::Scratch& s = c.s;
  const auto& list = s.active_list_;
  const auto& diagonal = c.model.diagonal_block();
  const auto d = [&](std::int32_t v) -> const Eigen::Matrix3d& {
    return s.blocks_[std::size_t(diagonal[std::size_t(v)])];
  };
  for (const std::int32_t v : list) s.q_.col(v) = -s.gradient_.col(v);
  lower_solve(c, s.q_, s.r_, true);  // r = l^-1 b
  double rz = 0;
  for (const std::int32_t v : list) {
    s.step_.col(v).setZero();  // y
    s.z_.col(v) = d(v) * s.r_.col(v);
    s.p_.col(v) = s.z_.col(v);
    rz += s.r_.col(v).dot(s.z_.col(v));
  }
  const double stop = c.settings.cg_relative_tolerance * std::sqrt(rz);
  int it = 0;
  while (it < c.settings.max_cg_iterations && std::sqrt(rz) > stop) {
    lower_solve(c, s.p_, s.trial_direction_, false);  // t = l^-T p
    for (const std::int32_t v : list) s.q_.col(v) = s.p_.col(v) - d(v) * s.trial_direction_.col(v);
    lower_solve(c, s.q_, s.q_, true);  // in place: row v reads only rows before it
    double pq = 0;
    for (const std::int32_t v : list) {
      s.q_.col(v) += s.trial_direction_.col(v);
      pq += s.p_.col(v).dot(s.q_.col(v));
    }
    if (!(pq > 0)) break;
    const double alpha = rz / pq;
    double rz_next = 0;
    for (const std::int32_t v : list) {
      s.step_.col(v) += alpha * s.p_.col(v);
      s.r_.col(v) -= alpha * s.q_.col(v);
      s.z_.col(v) = d(v) * s.r_.col(v);
      rz_next += s.r_.col(v).dot(s.z_.col(v));
    }
    const double beta = rz_next / rz;
    for (const std::int32_t v : list) s.p_.col(v) = s.z_.col(v) + beta * s.p_.col(v);
    rz = rz_next;
    ++it;
  }
  for (const std::int32_t v : list) s.q_.col(v) = s.step_.col(v);
  lower_solve(c, s.q_, s.step_, false);  // step = l^-T y
  return it;
}

// gauss_seidel_cg on the packed active system (active_system.hpp): the same step.
int packed_gauss_seidel_cg(Context& c) {
  Solver::Scratch& s = c.s;
  const auto& list = s.active_list_;
  s.system_.pack({c.model.block_start(), c.model.block_column(), c.model.diagonal_block(),
                  s.blocks_, s.block_inverse_, list, s.active_});
  const auto na = static_cast<Eigen::Index>(list.size());
  s.packed_rhs_.resize(3, na);
  for (Eigen::Index i = 0; i < na; ++i)
    s.packed_rhs_.col(i) = -s.gradient_.col(list[std::size_t(i)]);
  const int it = s.system_.gauss_seidel_cg(s.packed_rhs_, c.settings.cg_relative_tolerance,
                                           c.settings.max_cg_iterations, s.packed_step_);
  for (Eigen::Index i = 0; i < na; ++i) s.step_.col(list[std::size_t(i)]) = s.packed_step_.col(i);
  return it;
}

}  // namespace

int solve_newton_system(Context& c) {
  Solver::Scratch& s = c.s;
  if (c.settings.preconditioner == Preconditioner::symmetric_gauss_seidel &&
      c.settings.packed_systems) {
    s.step_.resize(3, c.nv);
    return packed_gauss_seidel_cg(c);
  }
  for (auto* m : {&s.step_, &s.r_, &s.z_, &s.p_, &s.q_, &s.trial_direction_}) m->resize(3, c.nv);
  return c.settings.preconditioner == Preconditioner::block_jacobi ? jacobi_cg(c)
                                                                   : gauss_seidel_cg(c);
}

}  // namespace conform::membrane::solver_detail
