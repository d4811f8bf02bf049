// A console reporter that also prints, after the run, the ratio of each benchmark's median
// (or single) CPU time to its baseline's, measured in the same process.
//
// Usage: register pairs with add_ratio("BM_Kernel/1024", "BM_Baseline/1024") and call
// run_with_ratios(argc, argv) from main. With --benchmark_repetitions=N the medians are used.
#pragma once

#include <benchmark/benchmark.h>

#include <cstdio>
#include <map>
#include <string>
#include <vector>

namespace conform::bench {

struct RatioPair {
  std::string kernel, baseline, label;
  bool real_time = false;  // wall time: for work done in child processes, which CPU time misses
};

inline std::vector<RatioPair>& ratio_pairs() {
  static std::vector<RatioPair> pairs;
  return pairs;
}
inline void add_ratio(std::string kernel, std::string baseline, std::string label = {},
                      bool real_time = false) {
  ratio_pairs().push_back({std::move(kernel), std::move(baseline), std::move(label), real_time});
}

class RatioReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& run : runs) {
      // Prefer the median aggregate when repetitions are used, else the single run.
      const std::string name = run.run_name.str();
      // CPU time: on a shared, noisy machine it is steadier than wall time for one thread.
      const double t = run.GetAdjustedCPUTime(), wall = run.GetAdjustedRealTime();
      if (run.run_type == Run::RT_Aggregate) {
        if (run.aggregate_name == "median") medians_[name] = t, real_medians_[name] = wall;
      } else if (!medians_.count(name) || singles_.count(name)) {
        singles_[name] = t;
        if (!medians_.count(name)) medians_[name] = t, real_medians_[name] = wall;
      }
    }
  }
  void Finalize() override {
    ConsoleReporter::Finalize();
    std::printf(
        "\nRatios (kernel CPU time / baseline CPU time, same run; < 1 means faster;"
        " [wall]: wall times):\n");
    for (const auto& p : ratio_pairs()) {
      const auto& times = p.real_time ? real_medians_ : medians_;
      auto k = times.find(p.kernel), b = times.find(p.baseline);
      if (k == times.end() || b == times.end()) continue;
      std::printf(
          "  %-48s %-40s %7.3f\n", p.kernel.c_str(),
          ((p.label.empty() ? "vs " + p.baseline : p.label) + (p.real_time ? " [wall]" : ""))
              .c_str(),
          k->second / b->second);
    }
    std::fflush(stdout);
  }

 private:
  std::map<std::string, double> medians_, real_medians_, singles_;
};

inline int run_with_ratios(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
#if defined(CONFORM_NATIVE_BUILD) && CONFORM_NATIVE_BUILD
  benchmark::AddCustomContext("conform_march_native", "on");
#else
  benchmark::AddCustomContext("conform_march_native", "off");
#endif
  RatioReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  benchmark::Shutdown();
  return 0;
}

}  // namespace conform::bench
