#include "conform/membrane/solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include <stdexcept>

#include "active_system.hpp"
#include "range_error.hpp"

namespace conform::membrane {
namespace {

constexpr std::int64_t kParallelElements = 4096;  // below this, threads cost more than they save

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

namespace {

// What the gradient and the potential need of an element at given positions: its corner forces
// (f1 = A t P beta_1 at corner 1, f2 = A t P beta_2 at corner 2, -(f1 + f2) at corner 0) and
// its energy A t psi, J. 56 bytes against the full state's 400: the passes over every element
// keep only these (the full state is rebuilt for the Hessian of the elements a step changes).
struct ElementForces {
  Eigen::Vector3d f1, f2;
  double energy = 0;
};

}  // namespace

struct Solver::Scratch {
  std::vector<ElementForces> forces_;        // every element at x
  std::vector<ElementForces> guess_forces_;  // every element at the alternative guess
  std::vector<ElementForces> trial_forces_;  // of changed_ at trial_ (line search)
  // The last solve's result and its elements' forces, of the model built as last_build_: an
  // element whose corners are where they were then is not evaluated again (a body at rest, whose
  // carried guess is the last solution, evaluates only its moving part).
  std::vector<ElementForces> last_forces_;
  Eigen::Matrix3Xd last_x_;
  std::uint64_t last_build_ = 0;
  std::vector<Eigen::Matrix3d> upper_;  // the changed elements' six upper Hessian blocks each
  std::vector<Eigen::Matrix3d> node_stiffness_, block_inverse_, blocks_;
  std::vector<std::uint8_t> free_;    // per vertex: may move in this solve
  std::vector<std::uint8_t> active_;  // per vertex: moves in this Newton step (a subset of free_)
  std::vector<std::int32_t> active_list_;        // the active vertices, ascending
  std::vector<std::int32_t> changed_, touched_;  // elements with an active corner; their corners
  std::vector<std::int32_t> changed_slot_;       // per element: its index in changed_, or -1
  std::vector<std::uint8_t> node_mark_;
  std::vector<std::int32_t> reached_, seed_of_;  // the active set's search (select_active)
  Eigen::Matrix3Xd predicted_, gradient_, step_, r_, z_, p_, q_, trial_, trial_direction_;
  Eigen::VectorXd inertia_weight_, node_residual_;
  ActiveSystem system_;  // the Newton system of the active nodes, packed
  Eigen::Matrix3Xd packed_rhs_, packed_step_;
};

Solver::Solver() : scratch_(std::make_unique<Scratch>()) {}
Solver::~Solver() = default;
Solver::Solver(Solver&&) noexcept = default;
Solver& Solver::operator=(Solver&&) noexcept = default;

namespace {

// One solve's input, state and scratch, shared by its phases.
struct Context {
  const Model& model;
  const StepInput& in;
  const SolverSettings& settings;
  Solver::Scratch& s;
  std::int64_t nv = 0, ne = 0;
  bool dynamic = false;
  int threads = 1;
  double tolerance = 0;  // Pa: relative_tolerance x the stress scale
  bool reuse = false;    // last_forces_ are of this model's elements at last_x_

  bool fixed(std::int64_t v) const {
    return in.fixed[static_cast<std::size_t>(v)] != 0 || model.node_area(std::int32_t(v)) <= 0;
  }
  bool parallel() const { return threads > 1 && ne > kParallelElements; }
};

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

detail::ElementState state_at(const Context& c, std::int64_t e,
                              const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  const mesh::Face& f = c.model.element_faces()[static_cast<std::size_t>(e)];
  return detail::element_forces(c.model.elements()[static_cast<std::size_t>(e)], x.col(f[0]),
                                x.col(f[1]), x.col(f[2]), c.model.lambda(), c.model.mu(),
                                c.model.wrinkling());
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
  for (Eigen::Index i = 0; i < na; ++i) s.packed_rhs_.col(i) = -s.gradient_.col(list[std::size_t(i)]);
  const int it = s.system_.gauss_seidel_cg(s.packed_rhs_, c.settings.cg_relative_tolerance,
                                           c.settings.max_cg_iterations, s.packed_step_);
  for (Eigen::Index i = 0; i < na; ++i) s.step_.col(list[std::size_t(i)]) = s.packed_step_.col(i);
  return it;
}

int conjugate_gradients(Context& c) {
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

SolveReport Solver::solve(const Model& model, const StepInput& input,
                          const SolverSettings& settings, Eigen::Ref<Eigen::Matrix3Xd> x) {
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
    report.cg_iterations += conjugate_gradients(c);
    if (!line_search(c, x)) break;
  }
  s.last_x_ = x;  // forces_ are of x's elements (line_search keeps them so)
  std::swap(s.last_forces_, s.forces_);
  s.last_build_ = model.build_id();
  return report;
}

}  // namespace conform::membrane
