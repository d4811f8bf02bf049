// Tear and drill on the procedural arm at the paper's size (5,120 faces; the paper's arm has
// 5,037) and at 50k, 500k and 2M faces, with the paper's Python timings beside ours as
// `speedup` counters (paper time / our time): tear 2437 ms, drill 274 ms. (The cut is in
// cut_bench.cpp.)
//
// Every operation runs in two modes, in the same process (the signatures without an index
// scan too: for one query a scan is cheaper than building an index):
//   index — through a FaceIndex kept in sync (built once per mesh state, outside the timing);
//   scan  — FaceSearch::Scan, one scan of every face (the former behaviour);
// and the run ends with the ratios index / scan of the median times.
// BM_Index* time the index's own upkeep (build, refit) and one segment query against a scan.
//
// Every benchmark times only the operation (manual time, in thread CPU time): restoring the
// mesh is not timed. Iteration counts are fixed (fewer at 500k and 2M faces), since the untimed
// set-up (copying a mesh of up to 2M faces) would otherwise dominate the run; each mesh is built
// once per process. Run with
//   --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// for medians.
#include <benchmark/benchmark.h>

#include <time.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include "conform/mesh/analysis.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/face_index.hpp"
#include "conform/mesh/procedural_arm.hpp"
#include "conform/mesh/tear.hpp"
#include "mesh_bench_util.hpp"

using namespace conform::mesh;
using conform::bench::speedup;
using conform::bench::timed;

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
  Tear tear(int mode) {
    TearOptions o;
    o.search = mode == 1 ? FaceSearch::Scan : FaceSearch::Index;
    return mode == 0 ? Tear(mesh, adjacency, index, o) : Tear(mesh, adjacency, o);
  }
  DrillResult drill(int mode, const DrillTool& tool, bool tube, double rings = 0) {
    DrillOptions o;
    o.search = mode == 1 ? FaceSearch::Scan : FaceSearch::Index;
    o.tube = tube;
    o.tube_ring_spacing = rings;
    return mode == 0 ? conform::mesh::drill(mesh, adjacency, index, tool, o)
                     : conform::mesh::drill(mesh, adjacency, tool, o);
  }
};

// One tear step (sample 50 of a 100-sample stroke, after 49 steps).
void tear_step(benchmark::State& state, int faces, int mode) {
  const Model& m = model(faces);
  int grew = 0;
  double total = 0;
  for (auto _ : state) {
    Work w(m);
    Tear tear = w.tear(mode);
    for (int i = 0; i < 50; ++i) tear.advance(arm_blade(i, 100));
    total += timed(state, [&] { grew += tear.advance(arm_blade(50, 100)).extended; });
  }
  state.counters["extended"] = grew == static_cast<int>(state.iterations());
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  speedup(state, kPaperTearSeconds, total);
}

// A whole 100-sample stroke (the first sample finds the blade's hit: index query or scan).
void tear100(benchmark::State& state, int faces, int mode) {
  const Model& m = model(faces);
  int steps = 0;
  double total = 0;
  for (auto _ : state) {
    Work w(m);
    total += timed(state, [&] {
      Tear tear = w.tear(mode);
      for (int i = 0; i < 100; ++i) tear.advance(arm_blade(i, 100));
      steps = tear.steps();
    });
  }
  state.counters["steps"] = steps;
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  speedup(state, kPaperTearSeconds, total);
}

// Drill through the forearm (both walls), radius 1 cm, with or without the tube wall (with
// intermediate rings at most twice the rim spacing apart: `rings` 2).
const DrillTool kDrill{{0, -0.2, 0.42}, {0, 0.2, 0.42}, 0.01};
void drill_bench(benchmark::State& state, int faces, int mode, bool tube, double rings = 0) {
  const Model& m = model(faces);
  DrillResult r;
  double total = 0;
  for (auto _ : state) {
    Work w(m);
    total += timed(state, [&] { r = w.drill(mode, kDrill, tube, rings); });
  }
  state.counters["holes"] = r.holes;
  state.counters["tubes"] = r.tubes;
  state.counters["tube_faces"] = r.tube_faces;
  state.counters["changes"] = static_cast<double>(r.changes.size());
  state.counters["rim_points"] = r.rim_vertices;
  state.counters["refinements"] = r.refinements;
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
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
