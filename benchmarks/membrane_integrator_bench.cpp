// The membrane step's numerical damping and its cost. A sheet attached to its targets and
// displaced rigidly in its plane is a set of undamped oscillators, omega^2 = k / rho_A (a rigid
// motion leaves the membrane unstrained). Backward Euler multiplies each step by
//   z = 1 / (1 + i omega dt):  |z| = (1 + (omega dt)^2)^(-1/2),  arg z = -atan(omega dt),
// so the period grows by T_num / T = omega dt / atan(omega dt) and the amplitude falls by
// |z|^(2 pi / atan(omega dt)) per period: a numerical damping ratio of about omega dt / 2.
// BM_Oscillation/<omega dt x 100> steps the sheet through five periods and reports the measured
// period and amplitude ratios beside these closed forms (counters *_theory); its time is
// compared with the same number of static solves (dt = 0) of the same sheet, the baseline: the
// dynamics' share of the step. Results in solver.hpp's header.
#include <benchmark/benchmark.h>

#include <Eigen/Cholesky>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "conform/membrane/solver.hpp"
#include "conform/mesh/primitives.hpp"
#include "ratio_reporter.hpp"

using namespace conform;

namespace {

constexpr double kOffset = 1e-3;  // m, the initial in-plane displacement
constexpr int kPeriods = 5;

struct AttachedSheet {
  mesh::SkinnedMesh mesh = mesh::make_sheet(4, 4, 0.1, 0.1);
  membrane::Model model;
  membrane::SkinMaterial material;
  membrane::SolverSettings settings;
  membrane::Solver solver;
  std::vector<std::uint8_t> fixed;

  AttachedSheet() {
    material.prestress = {0, 0};
    material.attachment_damping = 0;
    model.build(mesh.rest, mesh.faces, material);
    fixed.assign(std::size_t(mesh.vertex_count()), 0);
    settings.relative_tolerance = 1e-10;
  }
  double omega() const { return std::sqrt(material.attachment_stiffness / material.areal_density); }

  // One backward-Euler step (dt > 0) or static solve (dt = 0) from x with velocity v.
  void step(Eigen::Matrix3Xd& x, Eigen::Matrix3Xd& v, double dt) {
    const Eigen::Matrix3Xd zero = Eigen::Matrix3Xd::Zero(3, x.cols());
    const Eigen::Matrix3Xd start = x, predicted = x + dt * v;
    const membrane::StepInput in{mesh.rest,
                                 membrane::no_columns(),
                                 start,
                                 zero,
                                 fixed,
                                 dt,
                                 dt > 0
                                     ? Eigen::Ref<const Eigen::Matrix3Xd>(predicted)
                                     : Eigen::Ref<const Eigen::Matrix3Xd>(membrane::no_columns())};
    if (dt > 0) x = predicted;
    solver.solve(model, in, settings, x);
    if (dt > 0) v = (x - start) / dt;
  }
};

struct Measured {
  double period_ratio = 0, amplitude_per_period = 0;
};

// The x offset of node 0 over the steps: the period from its upward zero crossings (linear
// interpolation), the decay from the recurrence the steps obey.
Measured oscillate(AttachedSheet& s, double omega_dt, int* steps_taken) {
  const double dt = omega_dt / s.omega();
  Eigen::Matrix3Xd x = s.mesh.rest, v = Eigen::Matrix3Xd::Zero(3, x.cols());
  x.row(0).array() += kOffset;
  const double period = 2 * std::numbers::pi / s.omega();
  const int steps = int(std::ceil(kPeriods * period / dt * omega_dt / std::atan(omega_dt))) + 2;
  std::vector<double> u{kOffset};
  std::vector<double> crossings;
  for (int i = 1; i <= steps; ++i) {
    s.step(x, v, dt);
    u.push_back(x(0, 0) - s.mesh.rest(0, 0));
    if (u[i - 1] < 0 && u[i] >= 0) crossings.push_back((i - 1 + u[i - 1] / (u[i - 1] - u[i])) * dt);
  }
  *steps_taken = steps;
  Measured m;
  if (crossings.size() < 2) return m;
  const double measured_period =
      (crossings.back() - crossings.front()) / double(crossings.size() - 1);
  m.period_ratio = measured_period / period;
  // A damped sinusoid u_n = A r^n cos(n theta + phi) obeys u_{n+1} = a u_n - b u_{n-1} with
  // a = 2 r cos(theta), b = r^2: a and b by least squares over every step, then the decay
  // per measured period, r^(2 pi / theta).
  Eigen::Matrix2d normal = Eigen::Matrix2d::Zero();
  Eigen::Vector2d rhs = Eigen::Vector2d::Zero();
  for (std::size_t k = 1; k + 1 < u.size(); ++k) {
    const Eigen::Vector2d row(u[k], -u[k - 1]);
    normal += row * row.transpose();
    rhs += row * u[k + 1];
  }
  const Eigen::Vector2d ab = normal.ldlt().solve(rhs);
  const double r = std::sqrt(ab(1)), theta = std::acos(std::clamp(ab(0) / (2 * r), -1.0, 1.0));
  m.amplitude_per_period = std::pow(r, 2 * std::numbers::pi / theta);
  return m;
}

void BM_Oscillation(benchmark::State& state) {
  const double omega_dt = double(state.range(0)) / 100.0;
  Measured m;
  int steps = 0;
  for (auto _ : state) {
    AttachedSheet s;
    m = oscillate(s, omega_dt, &steps);
  }
  const double theta = std::atan(omega_dt);
  state.counters["steps"] = steps;
  state.counters["period_ratio"] = m.period_ratio;
  state.counters["period_ratio_theory"] = omega_dt / theta;
  state.counters["amp_per_period"] = m.amplitude_per_period;
  state.counters["amp_per_period_theory"] =
      std::pow(1 + omega_dt * omega_dt, -std::numbers::pi / theta);
}

// The baseline: as many static solves of the displaced sheet as BM_Oscillation takes steps.
void BM_StaticSolves(benchmark::State& state) {
  const double omega_dt = double(state.range(0)) / 100.0;
  AttachedSheet probe;
  int steps = 0;
  oscillate(probe, omega_dt, &steps);
  for (auto _ : state) {
    AttachedSheet s;
    Eigen::Matrix3Xd v = Eigen::Matrix3Xd::Zero(3, s.mesh.vertex_count());
    for (int i = 0; i < steps; ++i) {
      Eigen::Matrix3Xd x = s.mesh.rest;
      x.row(0).array() += kOffset;
      s.step(x, v, 0.0);
      benchmark::DoNotOptimize(x.data());
    }
  }
}

constexpr int kOmegaDt[] = {5, 10, 20, 50, 100, 200};  // omega dt x 100

}  // namespace

int main(int argc, char** argv) {
  auto* oscillation = benchmark::RegisterBenchmark("BM_Oscillation", BM_Oscillation);
  auto* statics = benchmark::RegisterBenchmark("BM_StaticSolves", BM_StaticSolves);
  for (const int w : kOmegaDt) {
    oscillation->Arg(w)->Unit(benchmark::kMillisecond);
    statics->Arg(w)->Unit(benchmark::kMillisecond);
    const std::string arg = "/" + std::to_string(w);
    conform::bench::add_ratio("BM_Oscillation" + arg, "BM_StaticSolves" + arg);
  }
  return conform::bench::run_with_ratios(argc, argv);
}
