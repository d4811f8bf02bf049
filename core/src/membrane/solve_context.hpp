// The membrane solver's shared state between its translation units (solver.cpp: the Newton
// loop and the element passes; assembly.cpp: the Newton system's blocks; linear_solve.cpp: its
// solution): the per-element forces, the scratch kept between solves, one solve's context, and
// the phases one file calls in another.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "active_system.hpp"
#include "conform/membrane/detail/cst_kernel.hpp"
#include "conform/membrane/solver.hpp"

namespace conform::membrane {
namespace solver_detail {

constexpr std::int64_t kParallelElements = 4096;  // below this, threads cost more than they save

// What the gradient and the potential need of an element at given positions: its corner forces
// (f1 = A t P beta_1 at corner 1, f2 = A t P beta_2 at corner 2, -(f1 + f2) at corner 0) and
// its energy A t psi, J. 56 bytes against the full state's 400: the passes over every element
// keep only these (the full state is rebuilt for the Hessian of the elements a step changes).
struct ElementForces {
  Eigen::Vector3d f1, f2;
  double energy = 0;
};

}  // namespace solver_detail

struct Solver::Scratch {
  using ElementForces = solver_detail::ElementForces;
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

namespace solver_detail {

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

// Element e's full state at x (its corners' positions), solver.cpp.
detail::ElementState state_at(const Context& c, std::int64_t e,
                              const Eigen::Ref<const Eigen::Matrix3Xd>& x);

// Phase 5b (assembly.cpp): the Newton system's blocks of the active rows at x.
void assemble(Context& c, const Eigen::Ref<const Eigen::Matrix3Xd>& x);

// Phase 6 (linear_solve.cpp): step_ = the Newton step over the active nodes, H step = -g, as
// the settings say; returns the conjugate-gradient iterations.
int solve_newton_system(Context& c);

}  // namespace solver_detail
}  // namespace conform::membrane
