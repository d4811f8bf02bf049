// What the mesh benchmarks (cut_bench, tear_drill_bench) share: the procedural arm at a face
// count, thread-CPU timing of one operation, and the paper's figure beside ours.
#pragma once

#include <benchmark/benchmark.h>

#include <time.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "conform/skin/procedural_arm.hpp"

namespace conform::bench {

/// 0 → the default arm (5,120 faces); else an arm of about that many faces.
inline skin::ArmOptions arm_with_faces(int faces) {
  skin::ArmOptions o;
  if (faces > 0) {
    // #F = 2 · rings · segments with rings ≈ 2.5 segments, as in the default arm.
    o.segments = static_cast<int>(std::lround(std::sqrt(faces / 5.0)));
    o.rings = static_cast<int>(std::lround(faces / (2.0 * o.segments)));
  }
  return o;
}

/// This thread's CPU time in seconds: a machine shared with other jobs does not inflate it, and
/// the operations timed are single-threaded.
inline double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
}

/// Times `op` alone as the iteration's manual time (the set-up before it is not timed).
/// Returns its seconds.
template <class Fn>
double timed(benchmark::State& state, Fn op) {
  const double t0 = thread_seconds();
  op();
  const double s = thread_seconds() - t0;
  state.SetIterationTime(s);
  return s;
}

/// The paper's time and ours per operation, and their ratio (paper / ours), as counters.
inline void speedup(benchmark::State& state, double paper_seconds, double total_seconds) {
  const auto n = std::max<benchmark::IterationCount>(state.iterations(), 1);
  const double ours = total_seconds / static_cast<double>(n);
  state.counters["ours_ms"] = ours * 1e3;
  state.counters["paper_ms"] = paper_seconds * 1e3;
  state.counters["speedup"] = paper_seconds / ours;
}

/// Collects the median manual (real) time of every benchmark, under its name without the
/// "/iterations:N" and "/manual_time" tags (a single run stands for its median); a derived
/// reporter prints its ratios in Finalize().
class ManualTimeMedians : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const auto& run : runs) {
      std::string name = run.run_name.str();
      for (const char* tag : {"/iterations:", "/manual_time"})
        if (const auto at = name.find(tag); at != std::string::npos)
          name.erase(at, name.find('/', at + 1) - at);
      const double t = run.GetAdjustedRealTime();
      if (run.run_type == Run::RT_Aggregate) {
        if (run.aggregate_name == "median") median_[name] = t;
      } else if (!median_.count(name) || single_.count(name)) {
        single_[name] = t;
        median_[name] = t;
      }
    }
  }

 protected:
  std::map<std::string, double> median_;

 private:
  std::map<std::string, double> single_;
};

}  // namespace conform::bench
