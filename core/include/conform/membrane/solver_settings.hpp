// What an application sets and reads of the skin's implicit solver (membrane/solver.hpp, inside
// the library): its stopping test, iteration budgets and preconditioner, and the report of one
// solve. The plugin's Material holds the settings; SkinnedSoftBody::last_solve() returns the
// report.
#pragma once

namespace conform::membrane {

/// How each Newton system's conjugate gradients are preconditioned.
enum class Preconditioner {
  /// M = D (the 3 x 3 diagonal blocks).
  block_jacobi,
  /// Symmetric block Gauss-Seidel, M = (D + L) D^-1 (D + L)^T, applied by Eisenstat's trick
  /// (one triangular sweep each way per iteration, about the cost of one Jacobi iteration).
  /// Fewer iterations than block_jacobi on the skin's systems (docs/notes/membrane.md).
  symmetric_gauss_seidel,
};

struct SolverSettings {
  /// Stop when the largest |nodal force| / (node area x S) over the free nodes is below this,
  /// where S is the material's stress scale (SkinMaterial::stress_scale: the larger pre-stress,
  /// or E without one). Dimensionless, so the same setting means the same accuracy at every
  /// stress level. Default 1.2e-3 (97 Pa for skin's 80.8 kPa pre-stress), converged for the
  /// tear-opening wound (docs/notes/membrane.md).
  double relative_tolerance = 1.2e-3;
  int max_newton_iterations = 40;
  int max_cg_iterations = 400;
  /// Each Newton system is solved until its residual is below this fraction of the gradient.
  double cg_relative_tolerance = 0.05;
  Preconditioner preconditioner = Preconditioner::symmetric_gauss_seidel;
  /// A Newton step moves only the free nodes near one whose residual exceeds
  /// max(relative_tolerance x S, local_fraction x the largest residual): after an edit the
  /// imbalance is local, and the rest of the mesh is already in balance to far better than it. In
  /// [0, 1); 0 moves every free node in every step. The stopping test is global either way.
  double local_fraction = 1e-2;
  /// ... where near is within local_reach decay lengths sqrt(E t / k_t) of the attachment
  /// (the distance over which it screens a load: about 4 cm for the default skin), > 0.
  double local_reach = 2;
  /// Solve each symmetric_gauss_seidel system on a packed copy of its active rows (contiguous
  /// memory, the same step bit for bit). false: in place over the whole mesh's arrays (the
  /// benchmarks' baseline).
  bool packed_systems = true;
  /// OpenMP threads for the element and node loops of large meshes (1: serial). The results do
  /// not depend on it (every sum is gathered per vertex in a fixed order).
  int threads = 1;
  /// Throws std::invalid_argument naming a field out of its range.
  void validate() const;
};

struct SolveReport {
  double initial_residual = 0;   // Pa, before the first Newton step
  double residual = 0;           // Pa, at the returned positions
  double relative_residual = 0;  // residual / S, the stopping test's measure (dimensionless)
  int newton_iterations = 0;
  int cg_iterations = 0;  // summed over the Newton iterations
  bool converged = false;
};

}  // namespace conform::membrane
