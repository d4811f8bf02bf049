// Cut, tear and drill on the procedural arm at the paper's size (5,120 faces; the paper's arm
// has 5,037) and at 50k, 500k and 2M faces, with the paper's Python timings beside ours as
// `speedup` counters (paper time / our time): cut 4666 ms, tear 2437 ms, drill 274 ms.
// Table 1 is reproduced by the Table1_* benchmarks: the cut's four subroutines, with the
// conformal (X·Π) and the Euclidean (n·x − d) predicates, in the same run.
//
// Every benchmark times only the operation (manual time, in thread CPU time): restoring the
// mesh is not timed. The tear and drill benchmarks run a fixed number of iterations, since
// their untimed set-up (copying a mesh of up to 2M faces) would otherwise dominate the run. Run
// with
// --benchmark_repetitions=5 --benchmark_report_aggregates_only=true for medians. CGAL's
// Polygon_mesh_processing::clip is not compared: libcgal-dev is not installed.
#include <benchmark/benchmark.h>

#include <time.h>

#include <cmath>
#include <map>

#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/procedural_arm.hpp"
#include "conform/mesh/tear.hpp"

using namespace conform::mesh;
using Plane = conform::cga::Plane<double>;

namespace {

constexpr double kPaperCutSeconds = 4.666645036;
constexpr double kPaperTearSeconds = 2.437;
constexpr double kPaperDrillSeconds = 0.274;
// Table 1 (GA column / Euclidean column), seconds.
constexpr double kPaperSub1Ga = 0.072434584, kPaperSub1Eu = 0.036439578;
constexpr double kPaperSub2Ga = 2.205727577, kPaperSub2Eu = 2.050984303;
constexpr double kPaperSub3 = 0.061544961, kPaperSub4 = 2.326937914;

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

// A plane across the forearm, slightly oblique (as the paper's Fig. 3 cut).
const Plane kCutPlane = Plane::from_normal_point({0.15, 0.1, 1.0}, {0.0, 0.0, 0.42});

void BM_Cut(benchmark::State& state) {
  const Model& m = model(static_cast<int>(state.range(0)));
  const CutOptions options{.cap = state.range(1) != 0};
  std::int32_t pieces = 0;
  double total = 0;
  for (auto _ : state) {
    SkinnedMesh mesh = m.mesh;
    Adjacency adjacency = m.adjacency;
    total += timed(state, [&] { pieces = cut(mesh, adjacency, kCutPlane, options).pieces.count; });
    benchmark::DoNotOptimize(pieces);
  }
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  state.counters["pieces"] = pieces;
  speedup(state, kPaperCutSeconds, total);
}
BENCHMARK(BM_Cut)
    ->ArgsProduct({{0, 50000, 500000, 2000000}, {0, 1}})
    ->ArgNames({"faces", "cap"})
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// The change alone (no mutation): classification, snapping, intersections, re-triangulation.
void BM_CutComputeOnly(benchmark::State& state) {
  const Model& m = model(static_cast<int>(state.range(0)));
  double total = 0;
  for (auto _ : state) {
    total += timed(state, [&] {
      CutResult r = compute_cut(m.mesh, kCutPlane);
      benchmark::DoNotOptimize(r.change.added_faces.data());
    });
  }
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  speedup(state, kPaperCutSeconds, total);
}
BENCHMARK(BM_CutComputeOnly)
    ->Arg(0)
    ->Arg(50000)
    ->Arg(500000)
    ->Arg(2000000)
    ->ArgName("faces")
    ->UseManualTime()
    ->Unit(benchmark::kMillisecond);

// Table 1, subroutine 1: vertex classification.
void BM_Table1_Sub1_Classify(benchmark::State& state) {
  const Model& m = model(0);
  const auto p = state.range(0) == 0 ? Predicates::Cga : Predicates::Euclidean;
  std::vector<double> d;
  double total = 0;
  for (auto _ : state) {
    total += timed(state, [&] {
      classify_vertices(m.mesh, kCutPlane, p, d);
      benchmark::DoNotOptimize(d.data());
    });
  }
  state.SetLabel(p == Predicates::Cga ? "CGA X.Pi" : "Euclidean n.x-d");
  speedup(state, p == Predicates::Cga ? kPaperSub1Ga : kPaperSub1Eu, total);
}
BENCHMARK(BM_Table1_Sub1_Classify)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("euclidean")
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// Subroutine 2: intersections and re-triangulation (compute_cut minus the classification it
// also does, which the Sub1 row measures separately; here timed whole).
void BM_Table1_Sub2_IntersectTriangulate(benchmark::State& state) {
  const Model& m = model(0);
  const CutOptions o{.predicates = state.range(0) == 0 ? Predicates::Cga : Predicates::Euclidean};
  double total = 0;
  for (auto _ : state) {
    total += timed(state, [&] {
      CutResult r = compute_cut(m.mesh, kCutPlane, o);
      benchmark::DoNotOptimize(r.change.added_faces.data());
    });
  }
  state.SetLabel(std::string(state.range(0) == 0 ? "CGA" : "Euclidean") + ", includes sub 1");
  speedup(state, state.range(0) == 0 ? kPaperSub2Ga : kPaperSub2Eu, total);
}
BENCHMARK(BM_Table1_Sub2_IntersectTriangulate)
    ->Arg(0)
    ->Arg(1)
    ->ArgName("euclidean")
    ->UseManualTime()
    ->Unit(benchmark::kMicrosecond);

// Subroutine 3: weights (and the other attributes) of the new vertices.
void BM_Table1_Sub3_Weights(benchmark::State& state) {
  const Model& m = model(0);
  const CutResult r = compute_cut(m.mesh, kCutPlane);
  double total = 0;
  for (auto _ : state) {
    SkinnedMesh mesh = m.mesh;
    total += timed(state, [&] { apply_vertices(mesh, r.change); });
    benchmark::DoNotOptimize(mesh.weights.data());
  }
  state.counters["new_vertices"] = static_cast<double>(r.change.new_vertices.size());
  speedup(state, kPaperSub3, total);
}
BENCHMARK(BM_Table1_Sub3_Weights)->UseManualTime()->Unit(benchmark::kMicrosecond);

// Subroutine 4: split into pieces (apply the faces, keep the adjacency, label components).
void BM_Table1_Sub4_Split(benchmark::State& state) {
  const Model& m = model(0);
  const CutResult r = compute_cut(m.mesh, kCutPlane);
  SkinnedMesh with_vertices = m.mesh;
  apply_vertices(with_vertices, r.change);
  double total = 0;
  for (auto _ : state) {
    SkinnedMesh mesh = with_vertices;
    Adjacency adjacency = m.adjacency;
    total += timed(state, [&] {
      apply_faces(mesh, r.change, &adjacency);
      const Pieces p = label_pieces(mesh);
      benchmark::DoNotOptimize(p.count);
    });
  }
  speedup(state, kPaperSub4, total);
}
BENCHMARK(BM_Table1_Sub4_Split)->UseManualTime()->Unit(benchmark::kMicrosecond);

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
