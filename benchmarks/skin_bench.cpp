// Skinning, one frame = per-bone coefficients from the pose + the vertex loop, in the same run:
//   CGA eq 17 (per-term down-projection)   vs matrix LBS (Eigen 4×4 hierarchy, blended 3×4)
//   versor blend                           vs dual-quaternion skinning
// on the procedural arm (default, 2,562 vertices; arm:20, 1,024,002 vertices) and on the
// largest rigged model of Debian's assimp-testmodels (FBX/animation_with_skeleton.fbx, 2,464
// vertices, 14 bones), with 4 influences, double precision, 1 and 2 OpenMP threads; and CGA vs
// matrix LBS in single precision on arm:20.
// Arguments: /model/threads with model 0 = arm, 1 = arm:20, 2 = the FBX model.
#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <memory>
#include <numbers>

#include "conform/io/import.hpp"
#include "conform/skin/skinner.hpp"

namespace {

using namespace conform;

// Debian's assimp-testmodels (the tests get this path from CMake; the benchmarks do not).
#ifndef CONFORM_ASSIMP_MODELS
#define CONFORM_ASSIMP_MODELS "/usr/share/assimp/models"
#endif

struct Setup {
  io::SkinnedModel model;
  skin::Pose pose;
  std::unique_ptr<skin::Skinner<double>> skinner;
  std::unique_ptr<skin::Skinner<float>> skinner_f;  // single precision, same model and pose
};

// A pose that moves every bone: the arm bent at shoulder, elbow and wrist with a twist and a
// dilated hand; a file model at the middle of its first animation.
Setup* setup(int which) {
  static std::unique_ptr<Setup> cache[3];
  auto& s = cache[which];
  if (s) return s.get();
  s = std::make_unique<Setup>();
  if (which < 2) {
    s->model = io::arm_model(which == 0 ? 1 : 20);
    s->pose = skin::Pose::rest(s->model.skeleton);
    using M = cga::Motor<double>;
    s->pose.apply_local(0, skin::Versor::from_motor(M::from_axis_angle({0.3, 1, 0}, 0.8)));
    s->pose.apply_local(1, skin::Versor::from_motor(M::from_axis_angle({1, 0, 0}, 1.4)));
    s->pose.apply_local(2, skin::Versor{M::from_axis_angle({0, 0.2, 1}, 1.0), 1.2});
  } else {
    // The file's weights sum to 0.94–1.38: normalized on import.
    s->model =
        io::import_model(std::string(CONFORM_ASSIMP_MODELS) + "/FBX/animation_with_skeleton.fbx");
    const auto& a = s->model.animations.at(0);
    a.sample(s->model.skeleton, 0.5 * a.duration(), skin::Blend::log, s->pose);
  }
  s->skinner = std::make_unique<skin::Skinner<double>>(s->model.skeleton, s->model.mesh.rest,
                                                       s->model.influences, 4);
  s->skinner_f = std::make_unique<skin::Skinner<float>>(s->model.skeleton, s->model.mesh.rest,
                                                        s->model.influences, 4);
  return s.get();
}

void run(benchmark::State& state, skin::SkinMode mode) {
  Setup* s = setup(static_cast<int>(state.range(0)));
  s->skinner->set_threads(static_cast<int>(state.range(1)));
  for (auto _ : state) {
    s->skinner->skin(s->pose, mode);
    benchmark::DoNotOptimize(s->skinner->output().x.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() *
                          static_cast<std::int64_t>(s->skinner->vertex_count()));
  state.counters["vertices"] = static_cast<double>(s->skinner->vertex_count());
  state.counters["bones"] = s->model.skeleton.bone_count();
}

void run_float(benchmark::State& state, skin::SkinMode mode) {
  Setup* s = setup(static_cast<int>(state.range(0)));
  s->skinner_f->set_threads(static_cast<int>(state.range(1)));
  for (auto _ : state) {
    s->skinner_f->skin(s->pose, mode);
    benchmark::DoNotOptimize(s->skinner_f->output().x.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() *
                          static_cast<std::int64_t>(s->skinner_f->vertex_count()));
}
void BM_CgaFloat(benchmark::State& state) {
  run_float(state, skin::SkinMode::cga);
}
void BM_MatrixLbsFloat(benchmark::State& state) {
  run_float(state, skin::SkinMode::matrix_lbs);
}

void BM_Cga(benchmark::State& state) {
  run(state, skin::SkinMode::cga);
}
void BM_MatrixLbs(benchmark::State& state) {
  run(state, skin::SkinMode::matrix_lbs);
}
void BM_Versor(benchmark::State& state) {
  run(state, skin::SkinMode::versor);
}
void BM_DualQuat(benchmark::State& state) {
  run(state, skin::SkinMode::dual_quaternion);
}

// Per-bone step alone (hierarchy walk + coefficients), where the algebra differs most.
void BM_CgaBonesOnly(benchmark::State& state) {
  Setup* s = setup(static_cast<int>(state.range(0)));
  for (auto _ : state) s->skinner->prepare(s->pose, skin::SkinMode::cga);
}
void BM_MatrixBonesOnly(benchmark::State& state) {
  Setup* s = setup(static_cast<int>(state.range(0)));
  for (auto _ : state) s->skinner->prepare(s->pose, skin::SkinMode::matrix_lbs);
}

void args(benchmark::internal::Benchmark* b) {
  for (int model : {0, 1, 2})
    for (int threads : {1, 2}) b->Args({model, threads});
  b->UseRealTime()->Unit(benchmark::kMicrosecond);
}

BENCHMARK(BM_Cga)->Apply(args);
BENCHMARK(BM_MatrixLbs)->Apply(args);
BENCHMARK(BM_Versor)->Apply(args);
BENCHMARK(BM_DualQuat)->Apply(args);
BENCHMARK(BM_CgaFloat)->Args({1, 1})->Args({1, 2})->UseRealTime()->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MatrixLbsFloat)
    ->Args({1, 1})
    ->Args({1, 2})
    ->UseRealTime()
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_CgaBonesOnly)->Arg(2)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_MatrixBonesOnly)->Arg(2)->Unit(benchmark::kMicrosecond);

// Ratios from medians of both clocks: CPU time (steadier for one thread on a shared machine)
// and real time (the only meaningful one for two threads and speed-ups).
class SkinReporter : public benchmark::ConsoleReporter {
 public:
  struct Pair {
    std::string kernel, baseline, label;
  };
  std::vector<Pair> pairs;

  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& r : runs) {
      const std::string name = r.run_name.str();
      if (r.run_type == Run::RT_Aggregate && r.aggregate_name != "median") continue;
      if (r.run_type != Run::RT_Aggregate && median_.count(name)) continue;
      median_[name] = {r.GetAdjustedRealTime(), r.GetAdjustedCPUTime()};
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf("\nRatios of medians (kernel / baseline; < 1 means faster):   real     cpu\n");
    for (const auto& p : pairs) {
      const auto k = median_.find(p.kernel), b = median_.find(p.baseline);
      if (k == median_.end() || b == median_.end()) continue;
      std::printf("  %-62s %7.3f %7.3f\n", p.label.c_str(), k->second.first / b->second.first,
                  k->second.second / b->second.second);
    }
    std::fflush(stdout);
  }

 private:
  std::map<std::string, std::pair<double, double>> median_;
};

}  // namespace

int main(int argc, char** argv) {
  SkinReporter reporter;
  auto add_ratio = [&](std::string k, std::string b, std::string label) {
    reporter.pairs.push_back({std::move(k), std::move(b), std::move(label)});
  };
  const char* model_names[] = {"arm", "arm:20 (1M vertices)", "animation_with_skeleton.fbx"};
  for (int m = 0; m < 3; ++m)
    for (int t : {1, 2}) {
      const std::string a = "/" + std::to_string(m) + "/" + std::to_string(t) + "/real_time";
      const std::string what = std::string(model_names[m]) + ", " + std::to_string(t) + "T";
      add_ratio("BM_Cga" + a, "BM_MatrixLbs" + a, "CGA / matrix LBS, " + what + " (goal <= 1)");
      add_ratio("BM_Cga" + a, "BM_DualQuat" + a, "CGA / DQ, " + what);
      add_ratio("BM_Versor" + a, "BM_DualQuat" + a, "versor blend / DQ, " + what);
    }
  for (int m = 0; m < 3; ++m)
    for (const char* k : {"BM_Cga", "BM_MatrixLbs", "BM_Versor", "BM_DualQuat"}) {
      const std::string base = std::string(k) + "/" + std::to_string(m);
      add_ratio(base + "/1/real_time", base + "/2/real_time",
                std::string(k) + " " + model_names[m] + ": speed-up 1T/2T (goal >= 1.8; real)");
    }
  for (int t : {1, 2}) {
    const std::string a = "/1/" + std::to_string(t) + "/real_time";
    add_ratio("BM_CgaFloat" + a, "BM_MatrixLbsFloat" + a,
              "float: CGA / matrix LBS, arm:20, " + std::to_string(t) + "T");
  }
  add_ratio("BM_CgaFloat/1/1/real_time", "BM_CgaFloat/1/2/real_time",
            "float: BM_CgaFloat arm:20: speed-up 1T/2T (real)");
  add_ratio("BM_CgaBonesOnly/2", "BM_MatrixBonesOnly/2", "per-bone step only, FBX model");
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
