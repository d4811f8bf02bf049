// The cut (Algorithm 1) on the procedural arm at the paper's size (5,120 faces; the paper's arm
// has 5,037) and at 50k, 500k and 2M faces, with and without caps, with the paper's Python
// timing beside ours as `speedup` counters (paper time / our time): cut 4666 ms. (The tear and
// drill benchmarks are in tear_drill_bench.cpp.)
//
// Table 1 is reproduced by the Table1_* benchmarks: the cut's four subroutines, with the
// conformal (X·Π) and the Euclidean (n·x − d) predicates, in the same run, the paper's figures
// beside ours as counters.
//
// Caps: cap:1 uses the build's best section triangulator (CGAL's constrained Delaunay when
// found), cap:ear ear clipping with Delaunay flips (cap.hpp).
//
// When CMake found CGAL (libcgal-dev), BM_CgalClip times CGAL's
// Polygon_mesh_processing::clip of the same mesh (as a Surface_mesh, built outside the timing)
// by the same plane, with clip_volume = cap; the run ends with the ratios CGAL / ours of the
// median times. CGAL's clip keeps one side; our cut keeps both and labels the pieces.
//
// BM_ApplyOnly and BM_LabelPiecesOnly time the two steps of cut() after compute_cut alone:
// applying the (capped) change with the adjacency kept, and labelling the pieces.
//
// Every benchmark times only the operation (manual time, in thread CPU time): restoring the
// mesh is not timed. The mesh is restored by assignment into one long-lived working copy, as a
// haptic loop keeps one mesh for its whole run: its arrays keep the room earlier cuts grew (one
// untimed cut first), so the timing is the steady state, not the first growth of a fresh copy's
// arrays (page faults of new memory). BM_CutCold at the paper's size times a fresh copy
// instead, for comparison. Iteration counts are fixed at 500k and 2M faces, where the untimed
// set-up (copying the mesh) would otherwise dominate the run. Run with
//   --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
// for medians.
#include <benchmark/benchmark.h>

#include <time.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <string>

#include "conform/mesh/analysis.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/detail/apply_steps.hpp"
#include "conform/mesh/detail/cut_predicates.hpp"
#include "conform/skin/procedural_arm.hpp"
#include "mesh_bench_util.hpp"

#if CONFORM_HAVE_CGAL
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/clip.h>
#include <CGAL/Surface_mesh.h>
#endif

using namespace conform::mesh;
using conform::bench::speedup;
using conform::bench::timed;
using conform::skin::make_arm;
using Plane = conform::cga::Plane<double>;

namespace {

constexpr double kPaperCutSeconds = 4.666645036;
// Table 1 (GA column / Euclidean column), seconds.
constexpr double kPaperSub1Ga = 0.072434584, kPaperSub1Eu = 0.036439578;
constexpr double kPaperSub2Ga = 2.205727577, kPaperSub2Eu = 2.050984303;
constexpr double kPaperSub3 = 0.061544961, kPaperSub4 = 2.326937914;

constexpr int kSizes[] = {0, 50000, 500000, 2000000};

// Arm sizes: 0 → the default arm (5,120 faces); else about that many faces.
struct Model {
  SkinnedMesh mesh;
  Adjacency adjacency;
};
const Model& model(int faces) {
  static std::map<int, Model> cache;
  auto it = cache.find(faces);
  if (it != cache.end()) return it->second;
  Model m{make_arm(conform::bench::arm_with_faces(faces)).mesh, {}};
  m.adjacency.build(m.mesh);
  return cache.emplace(faces, std::move(m)).first->second;
}

// A plane across the forearm, slightly oblique (as the paper's Fig. 3 cut).
const Eigen::Vector3d kCutNormal{0.15, 0.1, 1.0}, kCutPoint{0.0, 0.0, 0.42};
const Plane kCutPlane = Plane::from_normal_point(kCutNormal, kCutPoint);

// The whole operation: compute the change, apply it (keeping the adjacency), label pieces.
// cap: 0 none, 1 the best section triangulator of this build (CGAL's constrained Delaunay when
// found), 2 ear clipping + Delaunay flips.
// A working copy of a model: restored by assignment, which keeps its storage (warm), or made
// anew for every iteration (cold).
struct Work {
  SkinnedMesh mesh;
  Adjacency adjacency;
  void restore(const Model& m) {
    mesh = m.mesh;
    adjacency = m.adjacency;
  }
};

void cut_bench(benchmark::State& state, int faces, int cap, bool cold = false) {
  const Model& m = model(faces);
  const CutOptions options{
      .cap = cap != 0,
      .cap_triangulator = cap == 2 ? SectionTriangulator::EarClipping : SectionTriangulator::Best};
  if (cap != 0)
    state.SetLabel(cap == 2 || !has_cgal_triangulator() ? "ear clipping + flips"
                                                        : "CGAL constrained Delaunay");
  std::int32_t pieces = 0, capped = 0;
  double total = 0;
  std::optional<Work> work;
  auto next = [&]() -> Work& {
    if (cold || !work) work.emplace();
    work->restore(m);
    return *work;
  };
  if (!cold) {
    Work& w = next();  // one untimed cut warms the working copy
    cut(w.mesh, w.adjacency, kCutPlane, options);
  }
  for (auto _ : state) {
    Work& w = next();
    total += timed(state, [&] {
      const CutOutcome out = cut(w.mesh, w.adjacency, kCutPlane, options);
      pieces = out.pieces.count, capped = out.result.capped_loops;
    });
    benchmark::DoNotOptimize(pieces);
  }
  state.counters["faces"] = static_cast<double>(m.mesh.face_count());
  state.counters["pieces"] = pieces;
  if (cap) state.counters["capped_loops"] = capped;
  speedup(state, kPaperCutSeconds, total);
}

// The change alone (no mutation): classification, snapping, intersections, re-triangulation.
void compute_bench(benchmark::State& state, int faces) {
  const Model& m = model(faces);
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

// apply() alone: the cut's change (with caps) applied to a copy of the arm, keeping the
// adjacency, as cut() does between compute_cut and label_pieces. The drill and the tear apply
// their changes through the same function.
void apply_bench(benchmark::State& state, int faces) {
  const Model& m = model(faces);
  const CutResult r = compute_cut(m.mesh, kCutPlane, {.cap = true});
  double total = 0;
  Work w;
  w.restore(m);
  apply(w.mesh, r.change, &w.adjacency);  // warms the working copy
  for (auto _ : state) {
    w.restore(m);
    total += timed(state, [&] { apply(w.mesh, r.change, &w.adjacency); });
    benchmark::DoNotOptimize(w.mesh.faces.data());
  }
  state.counters["new_vertices"] = static_cast<double>(r.change.new_vertices.size());
  state.counters["added_faces"] = static_cast<double>(r.change.added_faces.size());
  state.counters["removed_faces"] = static_cast<double>(r.change.removed_faces.size());
}

// label_pieces alone, on the arm after the cut.
void label_bench(benchmark::State& state, int faces) {
  SkinnedMesh mesh = model(faces).mesh;
  Adjacency adjacency = model(faces).adjacency;
  cut(mesh, adjacency, kCutPlane, {.cap = true});
  std::int32_t pieces = 0;
  for (auto _ : state) {
    timed(state, [&] { pieces = label_pieces(mesh).count; });
    benchmark::DoNotOptimize(pieces);
  }
  state.counters["pieces"] = pieces;
}

#if CONFORM_HAVE_CGAL
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalMesh = CGAL::Surface_mesh<Kernel::Point_3>;

const CgalMesh& cgal_model(int faces) {
  static std::map<int, CgalMesh> cache;
  auto it = cache.find(faces);
  if (it != cache.end()) return it->second;
  const SkinnedMesh& m = model(faces).mesh;
  CgalMesh s;
  std::vector<CgalMesh::Vertex_index> v;
  v.reserve(static_cast<std::size_t>(m.vertex_count()));
  for (Eigen::Index i = 0; i < m.current.cols(); ++i)
    v.push_back(s.add_vertex(Kernel::Point_3(m.current(0, i), m.current(1, i), m.current(2, i))));
  for (const Face& f : m.faces)
    s.add_face(v[static_cast<std::size_t>(f[0])], v[static_cast<std::size_t>(f[1])],
               v[static_cast<std::size_t>(f[2])]);
  return cache.emplace(faces, std::move(s)).first->second;
}

// CGAL's clip by the same plane (n·x − n·p = 0), keeping its negative side.
void cgal_clip_bench(benchmark::State& state, int faces, bool cap) {
  const CgalMesh& base = cgal_model(faces);
  const Eigen::Vector3d n = kCutNormal.normalized();
  const Kernel::Plane_3 plane(n.x(), n.y(), n.z(), -n.dot(kCutPoint));
  std::size_t kept = 0;
  bool closed = false;
  double total = 0;
  for (auto _ : state) {
    CgalMesh mesh = base;
    total += timed(state, [&] {
      CGAL::Polygon_mesh_processing::clip(
          mesh, plane, CGAL::Polygon_mesh_processing::parameters::clip_volume(cap));
    });
    kept = mesh.number_of_faces();
    closed = CGAL::is_closed(mesh);
  }
  state.counters["faces"] = static_cast<double>(base.number_of_faces());
  state.counters["kept_faces"] = static_cast<double>(kept);
  state.counters["closed"] = closed;
  speedup(state, kPaperCutSeconds, total);
}
#endif

// Table 1, subroutine 1: vertex classification.
void table1_sub1(benchmark::State& state, bool euclidean) {
  const Model& m = model(0);
  const auto p = euclidean ? detail::Predicates::Euclidean : detail::Predicates::Cga;
  std::vector<double> d;
  double total = 0;
  for (auto _ : state) {
    total += timed(state, [&] {
      detail::classify_vertices(m.mesh, kCutPlane, p, d);
      benchmark::DoNotOptimize(d.data());
    });
  }
  state.SetLabel(euclidean ? "Euclidean n.x-d" : "CGA X.Pi");
  speedup(state, euclidean ? kPaperSub1Eu : kPaperSub1Ga, total);
}

// Subroutine 2: intersections and re-triangulation (compute_cut, which also classifies: the
// Sub1 row measures that part separately).
void table1_sub2(benchmark::State& state, bool euclidean) {
  const Model& m = model(0);
  const auto p = euclidean ? detail::Predicates::Euclidean : detail::Predicates::Cga;
  double total = 0;
  for (auto _ : state) {
    total += timed(state, [&] {
      CutResult r = detail::compute_cut(m.mesh, kCutPlane, {}, p);
      benchmark::DoNotOptimize(r.change.added_faces.data());
    });
  }
  state.SetLabel(std::string(euclidean ? "Euclidean" : "CGA") + ", includes sub 1");
  speedup(state, euclidean ? kPaperSub2Eu : kPaperSub2Ga, total);
}

// Subroutine 3: weights (and the other attributes) of the new vertices.
void table1_sub3(benchmark::State& state) {
  const Model& m = model(0);
  const CutResult r = compute_cut(m.mesh, kCutPlane);
  double total = 0;
  for (auto _ : state) {
    SkinnedMesh mesh = m.mesh;
    total += timed(state, [&] { detail::apply_vertices(mesh, r.change); });
    benchmark::DoNotOptimize(mesh.weights.data());
  }
  state.counters["new_vertices"] = static_cast<double>(r.change.new_vertices.size());
  speedup(state, kPaperSub3, total);
}

// Subroutine 4: split into pieces (apply the faces, keep the adjacency, label components).
void table1_sub4(benchmark::State& state) {
  const Model& m = model(0);
  const CutResult r = compute_cut(m.mesh, kCutPlane);
  SkinnedMesh with_vertices = m.mesh;
  detail::apply_vertices(with_vertices, r.change);
  double total = 0;
  for (auto _ : state) {
    SkinnedMesh mesh = with_vertices;
    Adjacency adjacency = m.adjacency;
    total += timed(state, [&] {
      detail::apply_faces(mesh, r.change, &adjacency);
      const Pieces p = label_pieces(mesh);
      benchmark::DoNotOptimize(p.count);
    });
  }
  speedup(state, kPaperSub4, total);
}

// Ratios of median manual times, measured in the same run.
class RatioReporter : public conform::bench::ManualTimeMedians {
 public:
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\nRatios of median times (same run):\n");
    auto ratio = [&](const std::string& a, const std::string& b, const char* what) {
      const auto ia = median_.find(a), ib = median_.find(b);
      if (ia != median_.end() && ib != median_.end())
        std::printf("  %-44s / %-40s %8.3f  %s\n", a.c_str(), b.c_str(), ia->second / ib->second,
                    what);
    };
    for (int faces : kSizes) {
      const std::string size = "/faces:" + std::to_string(faces);
      for (int cap = 0; cap < 2; ++cap) {
        const std::string tail = size + "/cap:" + std::to_string(cap);
        ratio("BM_CgalClip" + tail, "BM_Cut" + tail, "(> 1: our cut is faster than CGAL's clip)");
      }
      ratio("BM_CgalClip" + size + "/cap:1", "BM_Cut" + size + "/cap:ear",
            "(> 1: our cut, ear-clipped caps, is faster)");
      ratio("BM_Cut" + size + "/cap:1", "BM_Cut" + size + "/cap:0", "(capped / open)");
      ratio("BM_Cut" + size + "/cap:ear", "BM_Cut" + size + "/cap:0", "(ear-clipped caps / open)");
    }
    ratio("BM_Table1_Sub1_Classify/euclidean:0", "BM_Table1_Sub1_Classify/euclidean:1",
          "(CGA / Euclidean predicates)");
    ratio("BM_Table1_Sub2_IntersectTriangulate/euclidean:0",
          "BM_Table1_Sub2_IntersectTriangulate/euclidean:1", "(CGA / Euclidean predicates)");
    std::fflush(stdout);
  }
};

void register_all() {
  for (int faces : kSizes) {
    const int iterations = faces >= 2000000 ? 3 : faces >= 500000 ? 10 : 0;  // 0: automatic
    const std::string size = "/faces:" + std::to_string(faces);
    auto fixed = [&](benchmark::internal::Benchmark* b) {
      b->UseManualTime()->Unit(benchmark::kMillisecond);
      if (iterations > 0) b->Iterations(iterations);
    };
    for (int cap = 0; cap < 3; ++cap) {
      const std::string tail = size + (cap == 2 ? "/cap:ear" : "/cap:" + std::to_string(cap));
      fixed(benchmark::RegisterBenchmark(("BM_Cut" + tail).c_str(),
                                         [=](benchmark::State& s) { cut_bench(s, faces, cap); }));
      if (faces == 0 && cap < 2)
        fixed(benchmark::RegisterBenchmark(("BM_CutCold" + tail).c_str(), [=](benchmark::State& s) {
          cut_bench(s, faces, cap, true);
        }));
#if CONFORM_HAVE_CGAL
      if (cap < 2)
        fixed(benchmark::RegisterBenchmark(
            ("BM_CgalClip" + tail).c_str(),
            [=](benchmark::State& s) { cgal_clip_bench(s, faces, cap != 0); }));
#endif
    }
    fixed(benchmark::RegisterBenchmark(("BM_CutComputeOnly" + size).c_str(),
                                       [=](benchmark::State& s) { compute_bench(s, faces); }));
    fixed(benchmark::RegisterBenchmark(("BM_ApplyOnly" + size).c_str(),
                                       [=](benchmark::State& s) { apply_bench(s, faces); }));
    fixed(benchmark::RegisterBenchmark(("BM_LabelPiecesOnly" + size).c_str(),
                                       [=](benchmark::State& s) { label_bench(s, faces); }));
  }
  for (int e = 0; e < 2; ++e) {
    const std::string arg = "/euclidean:" + std::to_string(e);
    benchmark::RegisterBenchmark(("BM_Table1_Sub1_Classify" + arg).c_str(),
                                 [=](benchmark::State& s) { table1_sub1(s, e); })
        ->UseManualTime()
        ->Unit(benchmark::kMicrosecond);
    benchmark::RegisterBenchmark(("BM_Table1_Sub2_IntersectTriangulate" + arg).c_str(),
                                 [=](benchmark::State& s) { table1_sub2(s, e); })
        ->UseManualTime()
        ->Unit(benchmark::kMicrosecond);
  }
  benchmark::RegisterBenchmark("BM_Table1_Sub3_Weights", table1_sub3)
      ->UseManualTime()
      ->Unit(benchmark::kMicrosecond);
  benchmark::RegisterBenchmark("BM_Table1_Sub4_Split", table1_sub4)
      ->UseManualTime()
      ->Unit(benchmark::kMicrosecond);
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
