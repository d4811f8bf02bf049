// One implicit (backward Euler) step, or a static solve, of a membrane attached to its skinned
// targets, solved to a residual: Newton's method on the step's incremental potential, each
// Newton system solved by conjugate gradients (preconditioned as SolverSettings::preconditioner
// says), and a backtracking line search on the potential.
//
// The potential minimised over the free nodes' positions x (fixed nodes stay where they are):
//   Phi(x) = U(x)                                           membrane (model.hpp)
//          + sum_i 1/2 (x_i - T_i)^T K_i (x_i - T_i)          attachment to the targets T
//          + sum_i m_i / (2 dt^2) |x_i - xp_i|^2              inertia (xp: predicted positions)
//          + sum_i c A_i / (2 dt) |x_i - x0_i - dt vT_i|^2    damping relative to the targets
// with K_i = A_i (k_t (I - n n^T) + k_n n n^T) (n the target's unit normal; n = 0 gives k_t I),
// m_i = rho_A A_i and A_i the node's rest area. dt <= 0 drops inertia and damping: the static
// equilibrium. The residual is the largest nodal force imbalance per unit node area, in Pa
// (a traction), and the stopping test divides it by the material's stress scale S (the
// pre-stress, or the modulus without one): it means the same on every mesh and at every
// stress level.
//
// Backward Euler's numerical damping: an oscillator of angular frequency omega (the skin on its
// attachment: omega^2 = k / rho_A) is multiplied each step by z = 1 / (1 + i omega dt), so its
// amplitude by (1 + (omega dt)^2)^(-1/2) and its phase by atan(omega dt): a numerical damping
// ratio of about omega dt / 2 at small omega dt. Figures per scene: docs/notes/membrane.md.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "conform/membrane/model.hpp"
#include "conform/membrane/solver_settings.hpp"

namespace conform::membrane {

/// A 3 x 0 matrix that outlives every StepInput (the default of its optional fields).
inline const Eigen::Matrix3Xd& no_columns() {
  static const Eigen::Matrix3Xd none(3, 0);
  return none;
}

struct StepInput {
  /// Skinned targets T (3 x #V) and their unit normals (3 x #V, or empty: isotropic k_t).
  Eigen::Ref<const Eigen::Matrix3Xd> targets;
  Eigen::Ref<const Eigen::Matrix3Xd> target_normals;
  /// Positions at the start of the step x0 and the targets' velocities vT (3 x #V each, or
  /// empty when dt <= 0).
  Eigen::Ref<const Eigen::Matrix3Xd> start;
  Eigen::Ref<const Eigen::Matrix3Xd> target_velocities;
  /// 1 where the node is fixed at its given position (kinematic, pinned or without faces).
  std::span<const std::uint8_t> fixed;
  /// Step, s; <= 0 for the static equilibrium.
  double dt = 0;
  /// The predicted positions xp of the inertia term (3 x #V), x0 + dt v0 + dt^2 f_ext / m:
  /// the node's momentum, gravity and any external force act through it. Empty: x's given
  /// values are the prediction. The initial guess (x) is a separate choice.
  Eigen::Ref<const Eigen::Matrix3Xd> predicted = no_columns();
  /// Node masses, kg (empty: rho_A times the node's rest area). A host whose edits split and
  /// conserve mass (the Bullet plugin) passes its own books, so inertia and momentum agree.
  std::span<const double> masses = {};
  /// A second initial guess (3 x #V), or empty: Newton starts from whichever of x and this one
  /// has the lower Phi (fixed nodes keep x's values). A host passes the prediction in x and,
  /// here, e.g. the last solution moved with the targets, which is the better start for a body
  /// at rest against gravity (the prediction is dt^2 g off there).
  Eigen::Ref<const Eigen::Matrix3Xd> alternative_guess = no_columns();
};

class Solver {
 public:
  Solver();
  ~Solver();
  Solver(Solver&&) noexcept;
  Solver& operator=(Solver&&) noexcept;

  /// x: in, the initial guess (and the prediction xp unless StepInput::predicted is given;
  /// fixed nodes' values are kept; see also StepInput::alternative_guess);
  /// out, the solution. Throws std::invalid_argument on mismatched shapes.
  SolveReport solve(const Model& model, const StepInput& input, const SolverSettings& settings,
                    Eigen::Ref<Eigen::Matrix3Xd> x);

  struct Scratch;  // kept between calls: no allocation in a steady state (solver.cpp)

 private:
  std::unique_ptr<Scratch> scratch_;
};

}  // namespace conform::membrane
