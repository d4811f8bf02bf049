// Tear and drill on the procedural arm at the paper's size (5,120 faces; the paper's arm has
// 5,037) and at 50k, 500k and 2M faces, with the paper's Python timings beside ours as
// `speedup` counters (paper time / our time): tear 2437 ms, drill 274 ms. (Moved here from
// mesh_bench.cpp.)
//
// Every benchmark times only the operation (manual time, in thread CPU time): restoring the
// mesh is not timed. The benchmarks run a fixed number of iterations, since their untimed
// set-up (copying a mesh of up to 2M faces) would otherwise dominate the run. Run with
// --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians.
#include <benchmark/benchmark.h>

#include <time.h>

#include <cmath>
#include <map>

#include "conform/mesh/analysis.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/procedural_arm.hpp"
#include "conform/mesh/tear.hpp"

using namespace conform::mesh;

namespace {

constexpr double kPaperTearSeconds = 2.437;
constexpr double kPaperDrillSeconds = 0.274;

// Arm sizes: 0 → the default arm (5,120 faces); else about that many faces.
struct Model {
  SkinnedMesh mesh;
  Adjacency adjacency;
};
const Model& model(int faces) {
  static std::map<int, Model> cache;
  auto it = cache.find(faces);
  if (it != cache.end()) return it->second;
  ArmOptions o;
  if (faces > 0) {
    // #F = 2 · rings · segments with rings ≈ 2.5 segments, as in the default arm.
    o.segments = static_cast<int>(std::lround(std::sqrt(faces / 5.0)));
    o.rings = static_cast<int>(std::lround(faces / (2.0 * o.segments)));
  }
  Model m{make_arm(o).mesh, {}};
  m.adjacency.build(m.mesh);
  return cache.emplace(faces, std::move(m)).first->second;
}

// Times `op` alone (the set-up before it is not timed: these benchmarks use manual time) in
// this thread's CPU time, which a machine shared with other jobs does not inflate; the
// operations are single-threaded. Returns its seconds.
double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}
template <class Fn>
double timed(benchmark::State& state, Fn op) {
  const double t0 = thread_seconds();
  op();
  const double s = thread_seconds() - t0;
  state.SetIterationTime(s);
  return s;
}

// The paper's time and ours per operation, and their ratio (paper / ours).
void speedup(benchmark::State& state, double paper_seconds, double total_seconds) {
  const auto n = std::max<benchmark::IterationCount>(state.iterations(), 1);
  const double ours = total_seconds / static_cast<double>(n);
  state.counters["ours_ms"] = ours * 1e3;
  state.counters["paper_ms"] = paper_seconds * 1e3;
  state.counters["speedup"] = paper_seconds / ours;
}

ScalpelSample arm_blade(int i, int n) {
  const double z = 0.08 + 0.2 * i / (n - 1.0), a = 0.3 + 0.4 * i / (n - 1.0);
  return {double(i), {0, 0, z}, {0.2 * std::cos(a), 0.2 * std::sin(a), z}};
}

// One tear step (sample 50 of a 100-sample stroke, after 49 steps).
void BM_TearStep(benchmark::State& state) {
  const Model& m = model(static_cast<int>(state.range(0)));
  int grew = 0;
  double total = 0;
  for (auto _ : state) {
    SkinnedMesh mesh = m.mesh;
    Adjacency adjacency = m.adjacency;
    Tear tear(mesh, adjacency);
    for (int i = 0; i < 50; ++i) tear.advance(arm_blade(i, 100));
    total += timed(state, [&] { grew += tear.advance(arm_blade(50, 100)).extended; });
  }
  state.counters["extended"] = grew == static_cast<int>(state.iterations());
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  speedup(state, kPaperTearSeconds, total);
}
BENCHMARK(BM_TearStep)
    ->Arg(0)
    ->Arg(50000)
    ->Arg(500000)
    ->Arg(2000000)
    ->ArgName("faces")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(30);

// A whole 100-sample stroke (the first sample scans the faces once to start).
void BM_Tear100(benchmark::State& state) {
  const Model& m = model(static_cast<int>(state.range(0)));
  int steps = 0;
  double total = 0;
  for (auto _ : state) {
    SkinnedMesh mesh = m.mesh;
    Adjacency adjacency = m.adjacency;
    total += timed(state, [&] {
      Tear tear(mesh, adjacency);
      for (int i = 0; i < 100; ++i) tear.advance(arm_blade(i, 100));
      steps = tear.steps();
    });
  }
  state.counters["steps"] = steps;
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  speedup(state, kPaperTearSeconds, total);
}
BENCHMARK(BM_Tear100)
    ->Arg(0)
    ->Arg(50000)
    ->Arg(500000)
    ->Arg(2000000)
    ->ArgName("faces")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(10);

// Drill through the forearm (both walls), radius 1 cm.
void BM_Drill(benchmark::State& state) {
  const Model& m = model(static_cast<int>(state.range(0)));
  const DrillTool tool{{0, -0.2, 0.42}, {0, 0.2, 0.42}, 0.01};
  DrillResult r;
  double total = 0;
  for (auto _ : state) {
    SkinnedMesh mesh = m.mesh;
    Adjacency adjacency = m.adjacency;
    total += timed(state, [&] { r = drill(mesh, adjacency, tool); });
  }
  state.counters["holes"] = r.holes;
  state.counters["rim_points"] = r.rim_vertices;
  state.counters["refinements"] = r.refinements;
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  speedup(state, kPaperDrillSeconds, total);
}
BENCHMARK(BM_Drill)
    ->Arg(0)
    ->Arg(50000)
    ->Arg(500000)
    ->Arg(2000000)
    ->ArgName("faces")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(20);

}  // namespace

BENCHMARK_MAIN();
