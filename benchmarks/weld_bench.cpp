// The cost of welding an imported model at its seams (io::weld_model, mesh/weld.hpp) against
// assimp's own read of the same file with the same post-processing (io::import_flags()), in
// the same run, on the rigged models of assimp-testmodels. Ratio: weld / assimp read.
// Also the cost of isolating an import (ImportOptions::isolate: fork, import in the child,
// the model back as bytes) against the same import in this process; wall time, because the
// child's CPU time is not the process's. Ratio: isolated / in-process import.
#include <benchmark/benchmark.h>

#include <assimp/scene.h>
#include <assimp/Importer.hpp>
#include <filesystem>
#include <string>

#include "conform/io/import.hpp"
#include "conform/io/weld_model.hpp"
#include "ratio_reporter.hpp"

namespace {

const char* const kModels[] = {"X/Testwuson.X", "X/BCN_Epileptic.X",
                               "FBX/animation_with_skeleton.fbx", "X/anim_test.x"};
const std::string kRoot = "/usr/share/assimp/models/";

void assimp_read(benchmark::State& state, const std::string& file) {
  for (auto _ : state) {
    Assimp::Importer importer;
    const aiScene* scene = importer.ReadFile(file, conform::io::import_flags());
    benchmark::DoNotOptimize(scene);
  }
}

void weld(benchmark::State& state, const std::string& file) {
  conform::io::ImportOptions options;
  options.weld = false;
  const conform::io::SkinnedModel split = conform::io::import_model(file, options);
  for (auto _ : state) {
    state.PauseTiming();
    conform::io::SkinnedModel model = split;
    state.ResumeTiming();
    benchmark::DoNotOptimize(conform::io::weld_model(model).merged);
  }
  state.counters["vertices"] = split.mesh.vertex_count();
}

void import(benchmark::State& state, const std::string& file, bool isolate) {
  conform::io::ImportOptions options;
  options.isolate = isolate;
  for (auto _ : state) benchmark::DoNotOptimize(conform::io::import_model(file, options));
}

}  // namespace

int main(int argc, char** argv) {
  for (const char* name : kModels) {
    const std::string file = kRoot + name;
    if (!std::filesystem::exists(file)) continue;
    const std::string read = std::string("BM_AssimpRead/") + name,
                      welding = std::string("BM_Weld/") + name;
    benchmark::RegisterBenchmark(read.c_str(), [=](benchmark::State& s) {
      assimp_read(s, file);
    })->Unit(benchmark::kMillisecond);
    benchmark::RegisterBenchmark(welding.c_str(), [=](benchmark::State& s) {
      weld(s, file);
    })->Unit(benchmark::kMillisecond);
    conform::bench::add_ratio(welding, read, "weld/assimp");
    const std::string here = std::string("BM_Import/") + name,
                      isolated = std::string("BM_ImportIsolated/") + name;
    benchmark::RegisterBenchmark(here.c_str(), [=](benchmark::State& s) { import(s, file, false); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    benchmark::RegisterBenchmark(isolated.c_str(),
                                 [=](benchmark::State& s) { import(s, file, true); })
        ->Unit(benchmark::kMillisecond)
        ->UseRealTime();
    conform::bench::add_ratio(isolated, here, "isolated/in-process import", true);
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  conform::bench::RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}
