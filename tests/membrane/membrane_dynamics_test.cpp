// The membrane step's dynamics: inertia acts about the predicted positions (momentum and
// gravity), never about the initial guess; a free piece falls as backward Euler says, which is
// g t^2 / 2 to first order in dt; the guess changes where Newton starts, not the result.
#include <gtest/gtest.h>

#include <cmath>

#include "conform/membrane/solver.hpp"
#include "conform/mesh/primitives.hpp"

namespace conform::membrane {
namespace {

// A free 0.1 m sheet: no attachment, no damping, and no pre-stress (its free edges would pull
// in); a rigid motion leaves its membrane forces zero.
struct FreeSheet {
  mesh::SkinnedMesh mesh = mesh::make_sheet(4, 4, 0.1, 0.1);
  Model model;
  std::vector<std::uint8_t> fixed;
  SolverSettings settings;
  Solver solver;

  FreeSheet() {
    SkinMaterial m;
    m.prestress = {0, 0};
    m.attachment_stiffness = 0;
    m.attachment_normal_stiffness = 0;
    m.attachment_damping = 0;
    model.build(mesh.rest, mesh.faces, m);
    fixed.assign(std::size_t(mesh.vertex_count()), 0);
    settings.relative_tolerance = 1e-10;
  }

  // One step from x0 with velocity v0 under gravity g, starting Newton at `guess`; returns the
  // new positions.
  Eigen::Matrix3Xd step(const Eigen::Matrix3Xd& x0, const Eigen::Matrix3Xd& v0,
                        const Eigen::Vector3d& g, double dt, const Eigen::Matrix3Xd& guess,
                        SolveReport* report = nullptr) {
    const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Zero(3, x0.cols());
    const Eigen::Matrix3Xd predicted = (x0 + dt * v0).colwise() + dt * dt * g;
    const Eigen::Matrix3Xd none(3, 0);
    StepInput in{mesh.rest, none, x0, zero, fixed, dt, predicted};
    Eigen::Matrix3Xd x = guess;
    const SolveReport r = solver.solve(model, in, settings, x);
    EXPECT_TRUE(r.converged);
    if (report) *report = r;
    return x;
  }
};

TEST(MembraneDynamics, AFreeSheetKeepsItsMomentumWhateverTheGuess) {
  FreeSheet s;
  const double dt = 1e-3;
  const Eigen::Matrix3Xd x0 = s.mesh.rest;
  Eigen::Matrix3Xd v0 = Eigen::Matrix3Xd::Zero(3, x0.cols());
  v0.row(0).setConstant(1.0);  // 1 m/s along x
  // Starting at rest (the old anchor of the inertia term) or at the prediction: the same step.
  for (const Eigen::Matrix3Xd& guess : {x0, Eigen::Matrix3Xd(x0 + dt * v0)}) {
    const Eigen::Matrix3Xd x = s.step(x0, v0, Eigen::Vector3d::Zero(), dt, guess);
    const Eigen::Matrix3Xd v = (x - x0) / dt;
    EXPECT_NEAR(v.row(0).minCoeff(), 1.0, 1e-6);
    EXPECT_NEAR(v.row(0).maxCoeff(), 1.0, 1e-6);
    EXPECT_LT(v.bottomRows(2).cwiseAbs().maxCoeff(), 1e-6);
  }
}

// n backward-Euler steps from rest fall g dt^2 n (n + 1) / 2 = g t^2 / 2 (1 + dt / t).
double fall(FreeSheet& s, double dt, int n, double g) {
  Eigen::Matrix3Xd x = s.mesh.rest, v = Eigen::Matrix3Xd::Zero(3, x.cols());
  for (int i = 0; i < n; ++i) {
    const Eigen::Matrix3Xd next = s.step(x, v, Eigen::Vector3d(0, 0, -g), dt, x);
    v = (next - x) / dt;
    x = next;
  }
  EXPECT_LT((x.row(2).array() - x(2, 0)).abs().maxCoeff(), 1e-9);  // rigidly
  EXPECT_LT((x.topRows(2) - s.mesh.rest.topRows(2)).cwiseAbs().maxCoeff(), 1e-9);
  return s.mesh.rest(2, 0) - x(2, 0);
}

TEST(MembraneDynamics, AFreePieceFallsAsGTSquaredOverTwoToFirstOrder) {
  FreeSheet s;
  const double g = 9.81, t = 0.1;
  const double coarse = fall(s, t / 20, 20, g), fine = fall(s, t / 40, 40, g);
  const double exact = 0.5 * g * t * t;
  // Backward Euler's own solution, exactly.
  EXPECT_NEAR(coarse, g * (t / 20) * (t / 20) * 20 * 21 / 2, 1e-9 * exact);
  EXPECT_NEAR(fine, g * (t / 40) * (t / 40) * 40 * 41 / 2, 1e-9 * exact);
  // First order: the error is g t dt / 2, halved with the step.
  EXPECT_NEAR((coarse - exact) / exact, 1.0 / 20, 1e-9);
  EXPECT_NEAR((coarse - exact) / (fine - exact), 2.0, 1e-6);
}

TEST(MembraneDynamics, TheBetterOfTwoGuessesGivesTheSameStepInFewerIterations) {
  FreeSheet s;
  const double dt = 1e-3;
  const Eigen::Matrix3Xd x0 = s.mesh.rest;
  const Eigen::Matrix3Xd v0 = Eigen::Matrix3Xd::Constant(3, x0.cols(), 0.5);
  const Eigen::Vector3d g(0, 0, -9.81);
  SolveReport from_rest, from_prediction;
  const Eigen::Matrix3Xd a = s.step(x0, v0, g, dt, x0, &from_rest);
  const Eigen::Matrix3Xd b =
      s.step(x0, v0, g, dt, (x0 + dt * v0).colwise() + dt * dt * g, &from_prediction);
  EXPECT_LT((a - b).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_EQ(from_prediction.newton_iterations, 0);  // a rigid motion: the prediction is it
  EXPECT_GE(from_rest.newton_iterations, 1);
  // Offered both, the solver starts from the prediction.
  const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Zero(3, x0.cols());
  const Eigen::Matrix3Xd predicted = (x0 + dt * v0).colwise() + dt * dt * g;
  const Eigen::Matrix3Xd none(3, 0);
  const StepInput in{s.mesh.rest, none, x0, zero, s.fixed, dt, predicted, {}, predicted};
  Eigen::Matrix3Xd x = x0;
  EXPECT_EQ(s.solver.solve(s.model, in, s.settings, x).newton_iterations, 0);
  EXPECT_LT((x - predicted).cwiseAbs().maxCoeff(), 1e-15);
}

// The solver's sums are gathered per vertex and per element in a fixed order: a step of a
// pre-stressed, attached sheet large enough for the parallel loops (7200 elements) gives the
// same positions, bit for bit, and the same iterations on one thread and on two.
TEST(MembraneDynamics, TheStepDoesNotDependOnTheThreadCount) {
  const mesh::SkinnedMesh sheet = mesh::make_sheet(60, 60, 0.2, 0.2);
  Model model;
  model.build(sheet.rest, sheet.faces, SkinMaterial{});
  const Eigen::Index nv = sheet.rest.cols();
  std::vector<std::uint8_t> fixed(std::size_t(nv), 0);
  Eigen::Matrix3Xd bumped = sheet.rest;  // a bump lifted by 5 mm out of the sheet's plane
  for (Eigen::Index v = 0; v < nv; ++v)
    bumped(2, v) +=
        5e-3 * std::exp(-(sheet.rest.col(v).head<2>() - Eigen::Vector2d(0.07, 0.11)).squaredNorm() /
                        (0.03 * 0.03));
  const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Zero(3, nv), none(3, 0);
  const double dt = 1.0 / 60;
  const Eigen::Matrix3Xd predicted = bumped.colwise() + dt * dt * Eigen::Vector3d(0, 0, -9.81);
  const StepInput in{sheet.rest, none, bumped, zero, fixed, dt, predicted, {}, bumped};
  Eigen::Matrix3Xd x[2] = {predicted, predicted};
  SolveReport report[2];
  for (int t = 0; t < 2; ++t) {
    SolverSettings settings;
    settings.threads = t + 1;
    Solver solver;
    report[t] = solver.solve(model, in, settings, x[t]);
  }
  EXPECT_TRUE(report[0].converged);
  EXPECT_GE(report[0].newton_iterations, 2);
  EXPECT_EQ(report[0].newton_iterations, report[1].newton_iterations);
  EXPECT_EQ(report[0].cg_iterations, report[1].cg_iterations);
  EXPECT_EQ(report[0].residual, report[1].residual);
  EXPECT_TRUE((x[0].array() == x[1].array()).all());
}

}  // namespace
}  // namespace conform::membrane
