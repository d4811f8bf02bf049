// Phase timings of an edit (ApplyStats::Seconds): CPU time of the calling thread, steadier
// than wall time on a shared machine (the edits run on the caller's thread).
#pragma once

#include <ctime>

namespace conform::bullet {

inline double thread_seconds() {
  timespec t{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}

/// Seconds since `t`, which becomes now (one call per phase boundary).
inline double seconds_since(double& t) {
  const double now = thread_seconds();
  const double s = now - t;
  t = now;
  return s;
}

}  // namespace conform::bullet
