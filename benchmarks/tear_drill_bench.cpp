// Tear and drill on the procedural arm at the paper's size (5,120 faces; the paper's arm has
// 5,037) and at 50k, 500k and 2M faces, with the paper's Python timings beside ours as
// `speedup` counters (paper time / our time): tear 2437 ms, drill 274 ms. (The cut is in
// cut_bench.cpp.)
//
// Every operation runs in two modes, in the same process (the signatures without an index
// scan too: for one query a scan is cheaper than building an index):
//   index — through a FaceIndex kept in sync (built once per mesh state, outside the timing);
//   scan  — no index: one scan of every face (the former behaviour);
// and the run ends with the ratios index / scan of the median times.
// BM_Index* time the index's own upkeep (build, refit) and one segment query against a scan.
//
// Every benchmark times only the operation (manual time, in thread CPU time): restoring the
// mesh is not timed. The mesh is restored by assignment into one long-lived working copy, as a
// haptic loop keeps one mesh for its whole run: its arrays keep the room earlier edits grew
// (one untimed operation first), so the timing is the steady state, not the first growth of a
// fresh copy's arrays (page faults of new memory, which can double a 0.1 ms operation). The
// *Cold variants at the paper's size time a fresh copy instead, for comparison. Drill and tear
// report the faces they change (`affected_faces`) and the time per affected face: the cost
// follows the affected region, which grows with the mesh's density at a fixed tool size. Iteration
// counts are fixed (fewer at 500k and 2M faces), since the untimed set-up (copying a mesh of up to
// 2M faces) would otherwise dominate the run; each mesh is built once per process. Run with
//   --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// for medians.
#include <benchmark/benchmark.h>

#include <time.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "conform/mesh/analysis.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/face_index.hpp"
#include "conform/mesh/tear.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "mesh_bench_util.hpp"

using namespace conform::mesh;
using conform::bench::speedup;
using conform::bench::timed;
using conform::skin::make_arm;

namespace {

constexpr double kPaperTearSeconds = 2.437;
constexpr double kPaperDrillSeconds = 0.274;
constexpr int kSizes[] = {0, 50000, 500000, 2000000};
const char* const kModes[] = {"index", "scan"};

// Arm sizes: 0 → the default arm (5,120 faces); else about that many faces.
struct Model {
  SkinnedMesh mesh;
  Adjacency adjacency;
  FaceIndex index;
};
const Model& model(int faces) {
  static std::map<int, Model> cache;
  auto it = cache.find(faces);
  if (it != cache.end()) return it->second;
  Model m{make_arm(conform::bench::arm_with_faces(faces)).mesh, {}, {}};
  m.adjacency.build(m.mesh);
  m.index.build(m.mesh);
  return cache.emplace(faces, std::move(m)).first->second;
}

ScalpelSample arm_blade(int i, int n) {
  const double z = 0.08 + 0.2 * i / (n - 1.0), a = 0.3 + 0.4 * i / (n - 1.0);
  return {double(i), {0, 0, z}, {0.2 * std::cos(a), 0.2 * std::sin(a), z}};
}

// A working copy of a model; `mode` picks how the operation finds faces.
struct Work {
  SkinnedMesh mesh;
  Adjacency adjacency;
  FaceIndex index;
  // A copy has no spare capacity, where a long-lived index has some: give it back (untimed).
  explicit Work(const Model& m) : mesh(m.mesh), adjacency(m.adjacency), index(m.index) {
    index.reserve(m.mesh.face_count() / 8 + 1024);
  }
  // Back to the model's state, keeping this copy's storage (copy assignment reuses capacity).
  void restore(const Model& m) {
    mesh = m.mesh;
    adjacency = m.adjacency;
    index = m.index;
  }
  Tear tear(int mode, bool smooth_lips = false) {
    TearOptions o;
    o.smooth_lips = smooth_lips;
    return mode == 0 ? Tear(mesh, adjacency, index, o) : Tear(mesh, adjacency, o);
  }
  DrillResult drill(int mode, const DrillTool& tool, bool tube, double rings = 0) {
    DrillOptions o;
    o.tube = tube;
    o.tube_ring_spacing = rings;
    return mode == 0 ? conform::mesh::drill(mesh, adjacency, index, tool, o)
                     : conform::mesh::drill(mesh, adjacency, tool, o);
  }
};

std::int32_t removed_faces(const std::vector<TopologyChange>& changes) {
  std::size_t n = 0;
  for (const auto& ch : changes) n += ch.removed_faces.size();
  return static_cast<std::int32_t>(n);
}

// Per-iteration state: one long-lived working copy restored by assignment (warm), or a fresh
// copy per iteration (cold).
struct Workbench {
  const Model& model;
  bool cold;
  std::optional<Work> work;
  Work& next() {
    if (cold || !work)
      work.emplace(model);
    else
      work->restore(model);
    return *work;
  }
};

void affected(benchmark::State& state, std::int32_t faces, double total) {
  state.counters["affected_faces"] = faces;
  if (faces > 0)
    state.counters["us_per_affected_face"] =
        1e6 * total /
        static_cast<double>(std::max<benchmark::IterationCount>(state.iterations(), 1)) / faces;
}

// One tear step (sample 50 of a 100-sample stroke, after 49 steps).
void tear_step(benchmark::State& state, int faces, int mode) {
  const Model& m = model(faces);
  Workbench bench{m, false, {}};
  int grew = 0;
  std::int32_t split = 0;
  double total = 0;
  auto step = [&](benchmark::State* timing) {
    Work& w = bench.next();
    Tear tear = w.tear(mode);
    for (int i = 0; i < 50; ++i) tear.advance(arm_blade(i, 100));
    auto advance = [&] {
      const TearStep s = tear.advance(arm_blade(50, 100));
      grew += s.extended;
      split = removed_faces(s.changes);
    };
    if (timing)
      total += timed(*timing, advance);
    else
      advance();
  };
  step(nullptr);  // warms the working copy
  grew = 0;
  for (auto _ : state) step(&state);
  state.counters["extended"] = grew == static_cast<int>(state.iterations());
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  affected(state, split, total);
  speedup(state, kPaperTearSeconds, total);
}

// A whole 100-sample stroke (the first sample finds the blade's hit: index query or scan);
// smooth_lips (the smooth lips tear-opening tears with) against the default tear, its baseline.
void tear100(benchmark::State& state, int faces, int mode, bool smooth_lips = false) {
  const Model& m = model(faces);
  Workbench bench{m, false, {}};
  int steps = 0;
  std::int32_t split = 0;
  double total = 0;
  auto stroke = [&](Work& w) {
    Tear tear = w.tear(mode, smooth_lips);
    split = 0;
    for (int i = 0; i < 100; ++i) split += removed_faces(tear.advance(arm_blade(i, 100)).changes);
    steps = tear.steps();
  };
  stroke(bench.next());  // warms the working copy
  for (auto _ : state) {
    Work& w = bench.next();
    total += timed(state, [&] { stroke(w); });
  }
  state.counters["steps"] = steps;
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  affected(state, split, total);
  speedup(state, kPaperTearSeconds, total);
}

// Drill through the forearm (both walls), radius 1 cm, with or without the tube wall (with
// intermediate rings at most twice the rim spacing apart: `rings` 2).
const DrillTool kDrill{{0, -0.2, 0.42}, {0, 0.2, 0.42}, 0.01};
void drill_bench(benchmark::State& state, int faces, int mode, bool tube, double rings = 0,
                 bool cold = false) {
  const Model& m = model(faces);
  Workbench bench{m, cold, {}};
  DrillResult r;
  double total = 0;
  if (!cold) bench.next().drill(mode, kDrill, tube, rings);  // warms the working copy
  for (auto _ : state) {
    Work& w = bench.next();
    total += timed(state, [&] { r = w.drill(mode, kDrill, tube, rings); });
  }
  state.counters["holes"] = r.holes;
  state.counters["tubes"] = r.tubes;
  state.counters["tube_faces"] = r.tube_faces;
  state.counters["changes"] = static_cast<double>(r.changes.size());
  state.counters["rim_points"] = r.rim_vertices;
  state.counters["refinements"] = r.refinements;
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  affected(state, removed_faces(r.changes), total);
  speedup(state, kPaperDrillSeconds, total);
}

// The index's upkeep: a build (once per mesh state) and a refit (after positions move).
void index_build(benchmark::State& state, int faces) {
  const Model& m = model(faces);
  FaceIndex index;
  for (auto _ : state) timed(state, [&] { index.build(m.mesh); });
  state.counters["nodes"] = index.node_count();
  state.counters["depth"] = index.depth();
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
}
void index_refit(benchmark::State& state, int faces) {
  const Model& m = model(faces);
  FaceIndex index = m.index;
  for (auto _ : state) timed(state, [&] { index.refit(m.mesh); });
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
}
// One segment query (the drill's axis): index (mode 0) or scan (mode 1).
void segment_query(benchmark::State& state, int faces, int mode) {
  const Model& m = model(faces);
  std::size_t hits = 0;
  std::vector<SegmentHit> out;
  for (auto _ : state)
    timed(state, [&] {
      if (mode == 0)
        m.index.segment_hits(m.mesh, kDrill.base, kDrill.tip, out);
      else
        out = scan_segment_hits(m.mesh, kDrill.base, kDrill.tip);
      hits = out.size();
    });
  state.counters["hits"] = static_cast<double>(hits);
}

// Ratios of median manual times, measured in the same run.
class RatioReporter : public conform::bench::ManualTimeMedians {
 public:
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\nRatios of median times (same run; < 1: faster than the scan):\n");
    for (const auto& [name, t] : median_) {
      const auto at = name.find("/scan");
      if (at == std::string::npos) continue;
      for (const char* mode : {"index"}) {
        std::string other = name;
        other.replace(at + 1, 4, mode);
        auto it = median_.find(other);
        if (it != median_.end())
          std::printf("  %-60s / scan %8.3f\n", other.c_str(), it->second / t);
      }
    }
    std::fflush(stdout);
  }
};

void register_all() {
  for (int faces : kSizes) {
    const int it = faces >= 500000 ? 5 : 30;
    const std::string size = "/faces:" + std::to_string(faces);
    for (int mode = 0; mode < 2; ++mode) {
      const std::string tail = size + "/" + kModes[mode];
      benchmark::RegisterBenchmark(("BM_TearStep" + tail).c_str(),
                                   [=](benchmark::State& s) { tear_step(s, faces, mode); })
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond)
          ->Iterations(it);
      benchmark::RegisterBenchmark(("BM_Tear100" + tail).c_str(),
                                   [=](benchmark::State& s) { tear100(s, faces, mode); })
          ->UseManualTime()
          ->Unit(benchmark::kMillisecond)
          ->Iterations(faces >= 500000 ? 3 : 10);
      if (mode == 0)
        benchmark::RegisterBenchmark(("BM_Tear100Lips" + tail).c_str(),
                                     [=](benchmark::State& s) { tear100(s, faces, mode, true); })
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond)
            ->Iterations(faces >= 500000 ? 3 : 10);
      for (int variant = 0; variant < 3; ++variant) {
        const char* name[] = {"BM_Drill", "BM_DrillTube", "BM_DrillTubeRings"};
        benchmark::RegisterBenchmark((name[variant] + tail).c_str(),
                                     [=](benchmark::State& s) {
                                       drill_bench(s, faces, mode, variant > 0,
                                                   variant == 2 ? 2.0 : 0.0);
                                     })
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond)
            ->Iterations(it);
      }
    }
    if (faces == 0)
      for (int variant = 0; variant < 2; ++variant) {
        const char* name[] = {"BM_DrillCold", "BM_DrillTubeCold"};
        benchmark::RegisterBenchmark(
            (name[variant] + size + "/index").c_str(),
            [=](benchmark::State& s) { drill_bench(s, faces, 0, variant > 0, 0.0, true); })
            ->UseManualTime()
            ->Unit(benchmark::kMillisecond)
            ->Iterations(it);
      }
    benchmark::RegisterBenchmark(("BM_IndexBuild" + size).c_str(),
                                 [=](benchmark::State& s) { index_build(s, faces); })
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond)
        ->Iterations(faces >= 500000 ? 3 : 30);
    benchmark::RegisterBenchmark(("BM_IndexRefit" + size).c_str(),
                                 [=](benchmark::State& s) { index_refit(s, faces); })
        ->UseManualTime()
        ->Unit(benchmark::kMillisecond)
        ->Iterations(faces >= 500000 ? 5 : 100);
    for (int mode = 0; mode < 2; ++mode)
      benchmark::RegisterBenchmark(("BM_SegmentQuery" + size + "/" + kModes[mode]).c_str(),
                                   [=](benchmark::State& s) { segment_query(s, faces, mode); })
          ->UseManualTime()
          ->Unit(benchmark::kMicrosecond)
          ->Iterations(faces >= 500000 ? 5 : 200);
  }
}

}  // namespace

int main(int argc, char** argv) {
  register_all();
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
