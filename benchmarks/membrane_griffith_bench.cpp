// The cost of Griffith's growth decision against the solve it follows. A pinned slit sheet
// (membrane-griffith's at its defaults: 0.8 m square, a 5 cm slit, tip elements h / 16) is
// stretched at its border to half its Griffith stress. BM_GrowthDecision evaluates the energy
// release rate and mode mix at both tips (energy_release.hpp: two builds of the ring's elements
// and the lips' correlation) and compares G with G_c: what CrackedSheet::grow adds to a step
// without growth. BM_Solve, the baseline, solves the same sheet's static equilibrium from rest.
#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>

#include "conform/membrane/crack_growth.hpp"
#include "conform/membrane/slit_sheet.hpp"
#include "ratio_reporter.hpp"

using namespace conform;

namespace {

struct LoadedSlit {
  membrane::SkinMaterial material;
  membrane::SolverSettings solver;
  std::vector<membrane::CrackTip> tips;
  mesh::SkinnedMesh mesh;
  std::vector<std::uint8_t> fixed;
  Eigen::Matrix3Xd loaded;  // rest, the border stretched

  LoadedSlit() {
    material.prestress = {0, 0};
    material.toughness = 0.1;
    material.attachment_stiffness = 0;
    material.attachment_normal_stiffness = 0;
    material.wrinkling = false;
    solver.relative_tolerance = 1e-7;
    solver.max_cg_iterations = 20000;
    membrane::SlitSheetOptions o;
    o.width = 0.8;
    membrane::SlitSheet s = membrane::make_slit_sheet(o);
    mesh::apply(s.mesh, s.slit);
    mesh = s.mesh;
    fixed = s.border;
    fixed.resize(std::size_t(mesh.vertex_count()), 0);
    const double a = 0.025;
    for (const double sign : {1.0, -1.0}) {
      std::int32_t best = 0;
      const Eigen::Vector3d at(sign * a, 0, 0);
      for (std::int32_t v = 1; v < mesh.vertex_count(); ++v)
        if ((mesh.rest.col(v) - at).norm() < (mesh.rest.col(best) - at).norm()) best = v;
      tips.push_back({best, Eigen::Vector3d(sign, 0, 0)});
    }
    // Uniaxial sigma_yy at half Griffith's stress: e_yy = sigma / E, e_xx = -sigma / (2 E).
    const double E = material.youngs_modulus;
    const double sigma = 0.5 * std::sqrt(E * material.toughness / (std::numbers::pi * a));
    loaded = mesh.rest;
    for (Eigen::Index v = 0; v < loaded.cols(); ++v)
      if (fixed[std::size_t(v)])
        loaded.col(v) +=
            Eigen::Vector3d(-0.5 * sigma / E * loaded(0, v), sigma / E * loaded(1, v), 0);
  }
  membrane::CrackedSheet sheet() const {
    membrane::CrackedSheet s(mesh, fixed, tips, material, solver);
    s.positions() = loaded;
    return s;
  }
};

const LoadedSlit& loaded_slit() {
  static const LoadedSlit slit;
  return slit;
}

void BM_GrowthDecision(benchmark::State& state) {
  const LoadedSlit& slit = loaded_slit();
  membrane::CrackedSheet sheet = slit.sheet();
  sheet.solve();
  membrane::EnergyReleaseOptions domain;
  domain.domain_radius = 0.5 * 0.025;
  double g = 0;
  for (auto _ : state) {
    bool grows = false;
    for (const membrane::CrackTip& tip : slit.tips) {
      g = membrane::energy_release(sheet.mesh(), slit.material, sheet.positions(), tip, domain)
              .energy_release_rate;
      grows = grows || g >= slit.material.toughness;
    }
    benchmark::DoNotOptimize(grows);
  }
  state.counters["g_over_toughness"] = g / slit.material.toughness;  // 0.25 by Griffith
  state.counters["nodes"] = sheet.mesh().vertex_count();
}

void BM_Solve(benchmark::State& state) {
  const LoadedSlit& slit = loaded_slit();
  int newton = 0;
  for (auto _ : state) {
    state.PauseTiming();  // the model's build is not the solve's
    membrane::CrackedSheet sheet = slit.sheet();
    state.ResumeTiming();
    newton = sheet.solve().newton_iterations;
    benchmark::DoNotOptimize(sheet.positions().data());
  }
  state.counters["newton_iterations"] = newton;
}

}  // namespace

int main(int argc, char** argv) {
  benchmark::RegisterBenchmark("BM_GrowthDecision", BM_GrowthDecision)
      ->Unit(benchmark::kMillisecond);
  benchmark::RegisterBenchmark("BM_Solve", BM_Solve)->Unit(benchmark::kMillisecond);
  conform::bench::add_ratio("BM_GrowthDecision", "BM_Solve");
  return conform::bench::run_with_ratios(argc, argv);
}
