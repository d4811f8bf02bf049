#include "conform/membrane/solver.hpp"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <sstream>

#include <stdexcept>
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
  check(tolerance > 0 && std::isfinite(tolerance), "tolerance", tolerance, "> 0 Pa");
  check(max_newton_iterations >= 1, "max_newton_iterations", max_newton_iterations, ">= 1");
  check(max_cg_iterations >= 1, "max_cg_iterations", max_cg_iterations, ">= 1");
  check(threads >= 1, "threads", threads, ">= 1");
  check(cg_relative_tolerance > 0 && cg_relative_tolerance < 1, "cg_relative_tolerance",
        cg_relative_tolerance, "(0, 1)");
  check(local_fraction >= 0 && local_fraction < 1, "local_fraction", local_fraction, "[0, 1)");
  check(local_reach > 0 && std::isfinite(local_reach), "local_reach", local_reach, "> 0");
}

struct Solver::Scratch {
  std::vector<detail::ElementState> states_;
  std::vector<Eigen::Matrix3d> node_stiffness_, block_inverse_, blocks_;
  std::vector<std::uint8_t> free_;    // per vertex: may move in this solve
  std::vector<std::uint8_t> active_;  // per vertex: moves in this Newton step (a subset of free_)
  std::vector<std::int32_t> reached_, seed_of_;  // the active set's search (select_active)
  Eigen::Matrix3Xd predicted_, gradient_, step_, r_, z_, p_, q_, trial_;
  Eigen::VectorXd inertia_weight_, node_residual_;
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

  bool fixed(std::int64_t v) const {
    return in.fixed[static_cast<std::size_t>(v)] != 0 || model.node_area(std::int32_t(v)) <= 0;
  }
};

// Phase 1: nodal terms that do not change during the solve: attachment stiffness K_i and the
// inertia-damping weight w_i = m_i / dt^2 + c A_i / dt with its anchor
// (m_i / dt^2 xp_i + c A_i / dt (x0_i + dt vT_i)) / w_i (kept in predicted_).
void prepare_nodes(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  Solver::Scratch& s = c.s;
  const SkinMaterial& m = c.model.material();
  s.node_stiffness_.resize(static_cast<std::size_t>(c.nv));
  s.inertia_weight_.setZero(c.nv);
  s.predicted_ =
      c.in.predicted.cols() == c.nv ? Eigen::Matrix3Xd(c.in.predicted) : Eigen::Matrix3Xd(x);
  const bool normals = c.in.target_normals.cols() == c.nv;
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
      s.predicted_.col(v) = (inertia * x.col(v) +
                             damping * (c.in.start.col(v) + dt * c.in.target_velocities.col(v))) /
                            w;
  }
}

// Phase 2: per-element deformation gradient, stresses (parallel over elements).
void evaluate_elements(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  const auto& elements = c.model.elements();
  const auto& faces = c.model.element_faces();
  c.s.states_.resize(elements.size());
  const double lambda = c.model.lambda(), mu = c.model.mu();
#pragma omp parallel for schedule(static) \
    num_threads(c.threads) if (c.threads > 1 && c.ne > kParallelElements)
  for (std::int64_t e = 0; e < c.ne; ++e) {
    const mesh::Face& f = faces[static_cast<std::size_t>(e)];
    c.s.states_[static_cast<std::size_t>(e)] = detail::element_state(
        elements[static_cast<std::size_t>(e)], x.col(f[0]), x.col(f[1]), x.col(f[2]), lambda, mu);
  }
}

// Phi(x) (the membrane part from the element states of x).
double potential(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x) {
  double total = c.model.energy(x);
  for (std::int64_t v = 0; v < c.nv; ++v) {
    if (c.fixed(v)) continue;
    const Eigen::Vector3d d = x.col(v) - c.in.targets.col(v);
    total += 0.5 * d.dot(c.s.node_stiffness_[static_cast<std::size_t>(v)] * d);
    if (c.dynamic)
      total += 0.5 * c.s.inertia_weight_[v] * (x.col(v) - c.s.predicted_.col(v)).squaredNorm();
  }
  return total;
}

// Phase 3: gradient of Phi at the evaluated states, zero at fixed nodes (gather per vertex).
void gather_gradient(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x, Eigen::Matrix3Xd& g) {
  const auto& elements = c.model.elements();
  const auto& start = c.model.incidence_start();
  const auto& inc = c.model.incidence();
  g.resize(3, c.nv);
#pragma omp parallel for schedule(static) \
    num_threads(c.threads) if (c.threads > 1 && c.ne > kParallelElements)
  for (std::int64_t v = 0; v < c.nv; ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    if (!c.fixed(v)) {
      for (std::int32_t k = start[std::size_t(v)]; k < start[std::size_t(v) + 1]; ++k) {
        const std::int32_t e = inc[std::size_t(k)] / 3, corner = inc[std::size_t(k)] % 3;
        sum += elements[std::size_t(e)].area_thickness * c.s.states_[std::size_t(e)].p *
               detail::beta_of(elements[std::size_t(e)], corner);
      }
      sum += c.s.node_stiffness_[std::size_t(v)] * (x.col(v) - c.in.targets.col(v));
      if (c.dynamic) sum += c.s.inertia_weight_[v] * (x.col(v) - c.s.predicted_.col(v));
    }
    g.col(v) = sum;
  }
}

// The residual of each free node (|g_i| / A_i, Pa; 0 at fixed nodes) and the largest.
double residual(Context& c, const Eigen::Matrix3Xd& g) {
  double worst = 0;
  c.s.node_residual_.setZero(c.nv);
  for (std::int64_t v = 0; v < c.nv; ++v) {
    if (!c.s.free_[std::size_t(v)]) continue;
    c.s.node_residual_[v] = g.col(v).norm() / c.model.node_area(std::int32_t(v));
    worst = std::max(worst, c.s.node_residual_[v]);
  }
  return worst;
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
    return;
  }
  const double threshold = std::max(c.settings.tolerance, c.settings.local_fraction * worst);
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

// Phase 5: assemble the Hessian approximation's 3 x 3 blocks of the active rows, each row
// gathering from the elements it is a corner of (no two rows write one block, so the rows run
// in parallel), then the nodal attachment and inertia terms on the diagonal; and invert the
// diagonal blocks (block-Jacobi). Columns of inactive nodes are left out by hessian_apply.
void assemble(Context& c) {
  const auto& elements = c.model.elements();
  const auto& element_block = c.model.element_block();
  const auto& diagonal = c.model.diagonal_block();
  const auto& row_start = c.model.block_start();
  const auto& start = c.model.incidence_start();
  const auto& inc = c.model.incidence();
  const double lambda = c.model.lambda(), mu = c.model.mu();
  c.s.blocks_.resize(c.model.block_column().size());
  c.s.block_inverse_.resize(static_cast<std::size_t>(c.nv));
#pragma omp parallel for schedule(static) \
    num_threads(c.threads) if (c.threads > 1 && c.ne > kParallelElements)
  for (std::int64_t v = 0; v < c.nv; ++v) {
    Solver::Scratch& s = c.s;
    if (!s.active_[std::size_t(v)]) {
      s.block_inverse_[std::size_t(v)].setZero();
      continue;
    }
    for (std::int32_t j = row_start[std::size_t(v)]; j < row_start[std::size_t(v) + 1]; ++j)
      s.blocks_[std::size_t(j)].setZero();
    for (std::int32_t k = start[std::size_t(v)]; k < start[std::size_t(v) + 1]; ++k) {
      const std::int32_t e = inc[std::size_t(k)] / 3, a = inc[std::size_t(k)] % 3;
      Eigen::Matrix3d row[3];
      detail::hessian_row(elements[std::size_t(e)], s.states_[std::size_t(e)], lambda, mu, a, row);
      for (int b = 0; b < 3; ++b)
        s.blocks_[std::size_t(element_block[std::size_t(9 * e + 3 * a + b)])] += row[b];
    }
    Eigen::Matrix3d& k = s.blocks_[std::size_t(diagonal[std::size_t(v)])];
    k += s.node_stiffness_[std::size_t(v)];
    if (c.dynamic) k.diagonal().array() += s.inertia_weight_[v];
    const Eigen::Matrix3d regular =
        k + (1e-12 * k.trace() + 1e-300) * Eigen::Matrix3d::Identity();  // a lone node
    s.block_inverse_[std::size_t(v)] = regular.inverse();
  }
}

// out = H d over the active nodes (d's other entries are read as zero, out's are zero).
void hessian_apply(Context& c, const Eigen::Matrix3Xd& d, Eigen::Matrix3Xd& out) {
  const auto& start = c.model.block_start();
  const auto& column = c.model.block_column();
  out.resize(3, c.nv);
#pragma omp parallel for schedule(static) \
    num_threads(c.threads) if (c.threads > 1 && c.ne > kParallelElements)
  for (std::int64_t v = 0; v < c.nv; ++v) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    if (!c.s.active_[std::size_t(v)]) {
      out.col(v) = sum;
      continue;
    }
    for (std::int32_t j = start[std::size_t(v)]; j < start[std::size_t(v) + 1]; ++j) {
      const std::int32_t u = column[std::size_t(j)];
      if (c.s.active_[std::size_t(u)]) sum.noalias() += c.s.blocks_[std::size_t(j)] * d.col(u);
    }
    out.col(v) = sum;
  }
}

void precondition(const Context& c, const Eigen::Matrix3Xd& r, Eigen::Matrix3Xd& z) {
  z.resize(3, c.nv);
  for (std::int64_t v = 0; v < c.nv; ++v) z.col(v) = c.s.block_inverse_[std::size_t(v)] * r.col(v);
}

// Phase 6: H step = -g over the active nodes by preconditioned conjugate gradients; returns
// the iterations.
int conjugate_gradients(Context& c, const Eigen::Matrix3Xd& g, Eigen::Matrix3Xd& step) {
  Solver::Scratch& s = c.s;
  step.setZero(3, c.nv);
  s.r_.resize(3, c.nv);
  for (std::int64_t v = 0; v < c.nv; ++v)
    s.r_.col(v) = s.active_[std::size_t(v)] ? Eigen::Vector3d(-g.col(v)) : Eigen::Vector3d::Zero();
  precondition(c, s.r_, s.z_);
  s.p_ = s.z_;
  double rz = (s.r_.array() * s.z_.array()).sum();
  const double stop = c.settings.cg_relative_tolerance * s.r_.norm();
  int it = 0;
  while (it < c.settings.max_cg_iterations && s.r_.norm() > stop) {
    hessian_apply(c, s.p_, s.q_);
    const double pq = (s.p_.array() * s.q_.array()).sum();
    if (!(pq > 0)) break;  // no curvature left along p (cannot happen with a PSD H unless p = 0)
    const double alpha = rz / pq;
    step += alpha * s.p_;
    s.r_ -= alpha * s.q_;
    precondition(c, s.r_, s.z_);
    const double rz_next = (s.r_.array() * s.z_.array()).sum();
    s.p_ = s.z_ + (rz_next / rz) * s.p_;
    rz = rz_next;
    ++it;
  }
  return it;
}

// Phase 7: backtracking (Armijo) line search on Phi; returns false if no decrease was found.
bool line_search(Context& c, Eigen::Ref<Eigen::Matrix3Xd> x, const Eigen::Matrix3Xd& g,
                 const Eigen::Matrix3Xd& step, double phi) {
  const double slope = (g.array() * step.array()).sum();
  if (!(slope < 0)) return false;
  double alpha = 1;
  for (int k = 0; k < 30; ++k, alpha *= 0.5) {
    c.s.trial_ = x + alpha * step;
    const double trial = potential(c, c.s.trial_);
    if (std::isfinite(trial) && trial <= phi + 1e-4 * alpha * slope) {
      x = c.s.trial_;
      return true;
    }
  }
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
  if (input.fixed.size() != static_cast<std::size_t>(nv))
    throw std::invalid_argument("membrane solve: fixed has " + std::to_string(input.fixed.size()) +
                                " entries, the model has " + std::to_string(nv) + " vertices");
  Context c{model,        input,           settings, *scratch_, nv, model.element_count(),
            input.dt > 0, settings.threads};
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
  prepare_nodes(c, x);
  s.free_.resize(std::size_t(nv));
  for (Eigen::Index v = 0; v < nv; ++v) s.free_[std::size_t(v)] = !c.fixed(v);
  SolveReport report;
  for (;; ++report.newton_iterations) {
    evaluate_elements(c, x);
    gather_gradient(c, x, s.gradient_);
    report.residual = residual(c, s.gradient_);
    if (report.newton_iterations == 0) report.initial_residual = report.residual;
    if (report.residual <= settings.tolerance) {
      report.converged = true;
      break;
    }
    if (report.newton_iterations == settings.max_newton_iterations) break;
    select_active(c, report.residual, x);
    assemble(c);
    report.cg_iterations += conjugate_gradients(c, s.gradient_, s.step_);
    if (!line_search(c, x, s.gradient_, s.step_, potential(c, x))) break;
  }
  return report;
}

}  // namespace conform::membrane
