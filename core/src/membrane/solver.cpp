#include "conform/membrane/solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include <stdexcept>

#include "range_error.hpp"
#include "solve_context.hpp"

namespace conform::membrane {
namespace {

void require_cols(const Eigen::Ref<const Eigen::Matrix3Xd>& m, Eigen::Index cols, bool may_be_empty,
                  const char* name) {
  if (m.cols() == cols || (may_be_empty && m.cols() == 0)) return;
  std::ostringstream out;
  out << "membrane solve: " << name << " has " << m.cols() << " columns, the model has " << cols
      << " vertices";
  throw std::invalid_argument(out.str());
}

}  // namespace

void SolverSettings::validate() const {
  const RangeCheck check("membrane solver");
  check(relative_tolerance > 0 && std::isfinite(relative_tolerance), "relative_tolerance",
        relative_tolerance, "> 0 (dimensionless)");
  check(max_newton_iterations >= 1, "max_newton_iterations", max_newton_iterations, ">= 1");
  check(max_cg_iterations >= 1, "max_cg_iterations", max_cg_iterations, ">= 1");
  check(threads >= 1, "threads", threads, ">= 1");
  check(cg_relative_tolerance > 0 && cg_relative_tolerance < 1, "cg_relative_tolerance",
        cg_relative_tolerance, "(0, 1)");
  check(local_fraction >= 0 && local_fraction < 1, "local_fraction", local_fraction, "[0, 1)");
  check(local_reach > 0 && std::isfinite(local_reach), "local_reach", local_reach, "> 0");
}

Solver::Solver() : scratch_(std::make_unique<Scratch>()) {}
Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

namespace solver_detail {

detail::ElementState state_at(const Context& c, std::int64_t e,
                              const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  const mesh::Face& f = c.model.element_faces()[static_cast<std::size_t>(e)];
  return detail::element_forces(c.model.elements()[static_cast<std::size_t>(e)], x.col(f[0]),
                                x.col(f[1]), x.col(f[2]), c.model.lambda(), c.model.mu(),
                                c.model.wrinkling());
}

namespace {

// Phase 1: nodal terms that do not change during the solve: attachment stiffness K_i and the
// inertia-damping weight w_i = m_i / dt^2 + c A_i / dt with its anchor
// (m_i / dt^2 xp_i + c A_i / dt (x0_i + dt vT_i)) / w_i (kept in predicted_). The anchor is
// built from the prediction xp, never from the initial guess: the guess only says where Newton
// starts, the prediction carries the node's momentum and the external forces.
void prepare_nodes(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  Solver::Scratch& s = c.s;
  const SkinMaterial& m = c.model.material();
  s.node_stiffness_.resize(static_cast<std::size_t>(c.nv));
  s.inertia_weight_.setZero(c.nv);
  if (c.in.predicted.cols() == c.nv)
    s.predicted_ = c.in.predicted;
  else
    s.predicted_ = x;
  const bool normals = c.in.target_normals.cols() == c.nv;
#pragma omp parallel for schedule(static) num_threads(c.threads) if (c.parallel())
  for (std::int64_t v = 0; v < c.nv; ++v) {
    const double area = c.model.node_area(std::int32_t(v));
    Eigen::Matrix3d k = m.attachment_stiffness * area * Eigen::Matrix3d::Identity();
    if (normals) {
      const Eigen::Vector3d n = c.in.target_normals.col(v);
      k += (m.attachment_normal_stiffness - m.attachment_stiffness) * area * n * n.transpose();
    }
    s.node_stiffness_[static_cast<std::size_t>(v)] = k;
    if (!c.dynamic) continue;
    const double mass = c.in.masses.empty() ? m.areal_density * area : c.in.masses[std::size_t(v)];
    const double dt = c.in.dt, inertia = mass / (dt * dt),
                 damping = m.attachment_damping * area / dt, w = inertia + damping;
    s.inertia_weight_[v] = w;
    if (w > 0)
      s.predicted_.col(v) = (inertia * s.predicted_.col(v) +
                             damping * (c.in.start.col(v) + dt * c.in.target_velocities.col(v))) /
                            w;
  }
}

ElementForces forces_at(const Context& c, std::int64_t e,
                        const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  const detail::ElementState state = state_at(c, e, x);
  const detail::ElementRest& rest = c.model.elements()[static_cast<std::size_t>(e)];
  return {rest.area_thickness * state.p * rest.beta.col(0),
          rest.area_thickness * state.p * rest.beta.col(1), rest.area_thickness * state.psi};
}

// Element e's corners are bit for bit where the last solve left them: its forces are the ones
// kept then (an element's forces depend on its corners' positions only).
bool unmoved(const Context& c, std::int64_t e, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  for (const std::int32_t v : c.model.element_faces()[static_cast<std::size_t>(e)])
    if (std::memcmp(x.col(v).data(), c.s.last_x_.col(v).data(), 3 * sizeof(double)) != 0)
      return false;
  return true;
}

// Phase 2: every element's corner forces and energy (parallel over elements), reusing the last
// solve's of the elements that have not moved since. After a Newton step only the changed
// elements are evaluated again (line_search).
void evaluate_elements(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x,
                       std::vector<ElementForces>& forces) {
  forces.resize(static_cast<std::size_t>(c.ne));
#pragma omp parallel for schedule(static) num_threads(c.threads) if (c.parallel())
  for (std::int64_t e = 0; e < c.ne; ++e)
    forces[static_cast<std::size_t>(e)] = c.reuse && unmoved(c, e, x)
                                              ? c.s.last_forces_[static_cast<std::size_t>(e)]
                                              : forces_at(c, e, x);
}

// The nodal part of Phi at node v: 1/2 d^T K d + 1/2 w |x - xp|^2 (d = x - T).
double nodal_potential(const Context& c, std::int64_t v, const Eigen::Vector3d& x) {
  const Eigen::Vector3d d = x - c.in.targets.col(v);
  double total = 0.5 * d.dot(c.s.node_stiffness_[static_cast<std::size_t>(v)] * d);
  if (c.dynamic) total += 0.5 * c.s.inertia_weight_[v] * (x - c.s.predicted_.col(v)).squaredNorm();
  return total;
}

// Phi at x (after Phase 1) from its elements' forces: the membrane's energy plus the free
// nodes' own terms, summed in a fixed order (the same total at every thread count).
double total_potential(const Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x,
                       const std::vector<ElementForces>& forces) {
  double total = 0;
  for (const ElementForces& f : forces) total += f.energy;
  for (std::int64_t v = 0; v < c.nv; ++v)
    if (c.s.free_[std::size_t(v)]) total += nodal_potential(c, v, x.col(v));
  return total;
}

// Phase 3: the gradient of Phi, g = sum_e A_e t P_e beta_a + K_i (x_i - T_i) + w_i (x_i - xp_i),
// 0 at fixed nodes; and each node's residual |g_i| / A_i (Pa). scatter_element adds an element's
// change of corner forces (ElementForces) f1, f2 to its corners' gradients.
void scatter_element(Context& c, std::int64_t e, const Eigen::Vector3d& f1,
                     const Eigen::Vector3d& f2) {
  const mesh::Face& f = c.model.element_faces()[std::size_t(e)];
  c.s.gradient_.col(f[0]) -= f1 + f2;
  c.s.gradient_.col(f[1]) += f1;
  c.s.gradient_.col(f[2]) += f2;
}

void node_residual(Context& c, std::int64_t v) {
  if (!c.s.free_[std::size_t(v)]) {
    c.s.gradient_.col(v).setZero();
    c.s.node_residual_[v] = 0;
  } else {
    c.s.node_residual_[v] = c.s.gradient_.col(v).norm() / c.model.node_area(std::int32_t(v));
  }
}

// Node v's share of the elements' forces, gathered over its incidence in ascending element
// order: the same operations in the same order as scattering element by element, so the sum
// does not depend on how the nodes are shared among threads.
Eigen::Vector3d gather_element_forces(const Context& c, std::int64_t v) {
  const auto& start = c.model.incidence_start();
  const auto& inc = c.model.incidence();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::int32_t k = start[std::size_t(v)]; k < start[std::size_t(v) + 1]; ++k) {
    const std::int32_t e = inc[std::size_t(k)] / 3, corner = inc[std::size_t(k)] % 3;
    const ElementForces& f = c.s.forces_[std::size_t(e)];
    if (corner == 0)
      sum -= f.f1 + f.f2;
    else
      sum += corner == 1 ? f.f1 : f.f2;
  }
  return sum;
}

void gradient_all(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  Solver::Scratch& s = c.s;
  s.gradient_.resize(3, c.nv);
  s.node_residual_.resize(c.nv);
#pragma omp parallel for schedule(static) num_threads(c.threads) if (c.parallel())
  for (std::int64_t v = 0; v < c.nv; ++v) {
    s.gradient_.col(v) = gather_element_forces(c, v);
    if (s.free_[std::size_t(v)]) {
      s.gradient_.col(v) += s.node_stiffness_[std::size_t(v)] * (x.col(v) - c.in.targets.col(v));
      if (c.dynamic) s.gradient_.col(v) += s.inertia_weight_[v] * (x.col(v) - s.predicted_.col(v));
    }
    node_residual(c, v);
  }
}

// The initial guess, with the gradient and residuals at it (Phase 3): x, or the alternative
// where its Phi is lower (free nodes only), each guess's elements evaluated once. Both are
// always compared: a guess within the tolerance is no reason to skip the other, whose lower Phi
// may carry momentum or gravity (a free sheet's fall) below the tolerance's force.
void choose_guess(Context& c, Eigen::Ref<Eigen::Matrix3Xd> x) {
  Solver::Scratch& s = c.s;
  evaluate_elements(c, x, s.forces_);
  if (c.in.alternative_guess.cols() == c.nv && c.in.alternative_guess.allFinite()) {
    Eigen::Matrix3Xd& other = s.trial_;
    other = x;
    for (std::int64_t v = 0; v < c.nv; ++v)
      if (s.free_[std::size_t(v)]) other.col(v) = c.in.alternative_guess.col(v);
    evaluate_elements(c, other, s.guess_forces_);
    if (total_potential(c, other, s.guess_forces_) < total_potential(c, x, s.forces_)) {
      x = other;
      std::swap(s.forces_, s.guess_forces_);
    }
  }
  gradient_all(c, x);
}

// Phase 4: the nodes this Newton step moves. Right after an edit the imbalance is large and
// local (a crack tip: 1e5 Pa there, below the tolerance elsewhere), and a step over the whole
// mesh would spend its conjugate-gradient iterations on nodes that are in balance. So the step
// moves the free nodes within `local_reach` decay lengths sqrt(E t / k_t) (the distance over
// which the attachment screens a load) of a node whose residual exceeds
// max(tolerance, local_fraction * worst). The stopping test stays global, so the solution is
// the same; as the imbalance falls toward the tolerance the active set grows to wherever one
// remains.
void select_active(Context& c, double worst, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  Solver::Scratch& s = c.s;
  const SkinMaterial& m = c.model.material();
  const double decay = std::sqrt(m.youngs_modulus * m.thickness / m.attachment_stiffness);
  const double reach = c.settings.local_reach * decay;
  if (!(c.settings.local_fraction > 0) || !std::isfinite(reach)) {
    s.active_ = s.free_;
  } else {
    const double threshold = std::max(c.tolerance, c.settings.local_fraction * worst);
    s.active_.assign(std::size_t(c.nv), 0);
    s.seed_of_.assign(std::size_t(c.nv), -1);
    s.reached_.clear();
    for (std::int64_t v = 0; v < c.nv; ++v)
      if (s.node_residual_[v] > threshold) {
        s.active_[std::size_t(v)] = 1;
        s.seed_of_[std::size_t(v)] = std::int32_t(v);
        s.reached_.push_back(std::int32_t(v));
      }
    // Breadth first over the Hessian's graph, each node keeping the seed it was reached from.
    const auto& start = c.model.block_start();
    const auto& column = c.model.block_column();
    for (std::size_t k = 0; k < s.reached_.size(); ++k) {
      const std::int32_t v = s.reached_[k], seed = s.seed_of_[std::size_t(v)];
      for (std::int32_t j = start[std::size_t(v)]; j < start[std::size_t(v) + 1]; ++j) {
        const std::int32_t u = column[std::size_t(j)];
        if (s.seed_of_[std::size_t(u)] >= 0 || !s.free_[std::size_t(u)]) continue;
        if ((x.col(u) - x.col(seed)).norm() > reach) continue;
        s.seed_of_[std::size_t(u)] = seed;
        s.active_[std::size_t(u)] = 1;
        s.reached_.push_back(u);
      }
    }
  }
  s.active_list_.clear();
  for (std::int64_t v = 0; v < c.nv; ++v)
    if (s.active_[std::size_t(v)]) s.active_list_.push_back(std::int32_t(v));
}

// What a step of the active nodes changes: the elements with an active corner, and every corner
// of those (whose gradient changes with them).
void mark_changed(Context& c) {
  Solver::Scratch& s = c.s;
  const auto& start = c.model.incidence_start();
  const auto& inc = c.model.incidence();
  const auto& faces = c.model.element_faces();
  s.changed_slot_.assign(std::size_t(c.ne), -1);
  s.node_mark_.assign(std::size_t(c.nv), 0);
  s.changed_.clear();
  s.touched_.clear();
  for (const std::int32_t v : s.active_list_)
    for (std::int32_t k = start[std::size_t(v)]; k < start[std::size_t(v) + 1]; ++k) {
      const std::int32_t e = inc[std::size_t(k)] / 3;
      if (s.changed_slot_[std::size_t(e)] >= 0) continue;
      s.changed_slot_[std::size_t(e)] = std::int32_t(s.changed_.size());
      s.changed_.push_back(e);
      for (const std::int32_t u : faces[std::size_t(e)])
        if (!s.node_mark_[std::size_t(u)]) {
          s.node_mark_[std::size_t(u)] = 1;
          s.touched_.push_back(u);
        }
    }
}

// Phi(x + alpha step) - Phi(x): only the changed elements and the active nodes' own terms
// differ, so the difference is summed over them (cheap, and free of the cancellation that
// comparing two totals of the whole mesh suffers near the solution). The trial elements'
// forces are kept for the accepted step.
double potential_change(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x, double alpha) {
  Solver::Scratch& s = c.s;
  for (const std::int32_t v : s.active_list_) s.trial_.col(v) = x.col(v) + alpha * s.step_.col(v);
  const auto nc = static_cast<std::int64_t>(s.changed_.size());
  s.trial_forces_.resize(std::size_t(nc));
#pragma omp parallel for schedule(static) num_threads(c.threads) if (c.parallel())
  for (std::int64_t k = 0; k < nc; ++k)
    s.trial_forces_[std::size_t(k)] = forces_at(c, s.changed_[std::size_t(k)], s.trial_);
  double change = 0;  // summed in a fixed order: the same at every thread count
  for (std::int64_t k = 0; k < nc; ++k)
    change += s.trial_forces_[std::size_t(k)].energy -
              s.forces_[std::size_t(s.changed_[std::size_t(k)])].energy;
  for (const std::int32_t v : s.active_list_)
    change += nodal_potential(c, v, s.trial_.col(v)) - nodal_potential(c, v, x.col(v));
  return change;
}

// The step to trial_ is taken: x, the changed elements' forces, and the gradient updated by
// the change of each changed element's forces and of the active nodes' own terms.
void accept_step(Context& c, Eigen::Ref<Eigen::Matrix3Xd> x) {
  Solver::Scratch& s = c.s;
  for (std::size_t k = 0; k < s.changed_.size(); ++k) {
    const std::int32_t e = s.changed_[k];
    ElementForces& now = s.forces_[std::size_t(e)];
    scatter_element(c, e, s.trial_forces_[k].f1 - now.f1, s.trial_forces_[k].f2 - now.f2);
    now = s.trial_forces_[k];
  }
  for (const std::int32_t v : s.active_list_) {
    const Eigen::Vector3d dx = s.trial_.col(v) - x.col(v);
    s.gradient_.col(v) += s.node_stiffness_[std::size_t(v)] * dx;
    if (c.dynamic) s.gradient_.col(v) += s.inertia_weight_[v] * dx;
    x.col(v) = s.trial_.col(v);
  }
  for (const std::int32_t v : s.touched_) node_residual(c, v);
}

// Phase 7: backtracking (Armijo) line search on Phi; on success x, the changed elements'
// forces and the touched nodes' gradients are those of the new positions. Returns false if no
// decrease was found (x and the forces are left as they were).
bool line_search(Context& c, Eigen::Ref<Eigen::Matrix3Xd> x) {
  Solver::Scratch& s = c.s;
  double slope = 0;
  for (const std::int32_t v : s.active_list_) slope += s.gradient_.col(v).dot(s.step_.col(v));
  if (!(slope < 0)) return false;
  double alpha = 1;
  for (int k = 0; k < 30; ++k, alpha *= 0.5) {
    const double change = potential_change(c, x, alpha);
    if (!(std::isfinite(change) && change <= 1e-4 * alpha * slope)) continue;
    accept_step(c, x);
    return true;
  }
  for (const std::int32_t v : s.active_list_) s.trial_.col(v) = x.col(v);
  return false;
}

}  // namespace
}  // namespace solver_detail

SolveReport Solver::solve(const Model& model, const StepInput& input,
                          const SolverSettings& settings, Eigen::Ref<Eigen::Matrix3Xd> x) {
  using namespace solver_detail;
  settings.validate();
  const Eigen::Index nv = model.vertex_count();
  require_cols(x, nv, false, "x");
  require_cols(input.targets, nv, false, "targets");
  require_cols(input.target_normals, nv, true, "target_normals");
  require_cols(input.predicted, nv, true, "predicted");
  require_cols(input.alternative_guess, nv, true, "alternative_guess");
  if (input.fixed.size() != static_cast<std::size_t>(nv))
    throw std::invalid_argument("membrane solve: fixed has " + std::to_string(input.fixed.size()) +
                                " entries, the model has " + std::to_string(nv) + " vertices");
  Context c{model,        input,           settings, *scratch_, nv, model.element_count(),
            input.dt > 0, settings.threads};
  c.tolerance = settings.relative_tolerance * model.material().stress_scale();
  Scratch& s = *scratch_;
  if (!input.masses.empty() && input.masses.size() != static_cast<std::size_t>(nv))
    throw std::invalid_argument("membrane solve: masses has " +
                                std::to_string(input.masses.size()) + " entries, the model has " +
                                std::to_string(nv) + " vertices");
  if (c.dynamic) {
    require_cols(input.start, nv, false, "start");
    require_cols(input.target_velocities, nv, false, "target_velocities");
  }
  if (!x.allFinite()) throw std::invalid_argument("membrane solve: x holds a non-finite value");
  c.reuse = model.build_id() != 0 && s.last_build_ == model.build_id() && s.last_x_.cols() == nv &&
            s.last_forces_.size() == std::size_t(c.ne);
  prepare_nodes(c, x);
  s.free_.resize(std::size_t(nv));
  for (Eigen::Index v = 0; v < nv; ++v) s.free_[std::size_t(v)] = !c.fixed(v);
  choose_guess(c, x);
  s.trial_ = x;
  SolveReport report;
  for (;; ++report.newton_iterations) {
    report.residual = s.node_residual_.size() ? s.node_residual_.maxCoeff() : 0.0;
    report.relative_residual = report.residual / model.material().stress_scale();
    if (report.newton_iterations == 0) report.initial_residual = report.residual;
    if (report.residual <= c.tolerance) {
      report.converged = true;
      break;
    }
    if (report.newton_iterations == settings.max_newton_iterations) break;
    select_active(c, report.residual, x);
    mark_changed(c);
    assemble(c, x);
    report.cg_iterations += solve_newton_system(c);
    if (!line_search(c, x)) break;
  }
  s.last_x_ = x;  // forces_ are of x's elements (line_search keeps them so)
  std::swap(s.last_forces_, s.forces_);
  s.last_build_ = model.build_id();
  return report;
}

}  // namespace conform::membrane