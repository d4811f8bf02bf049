// DIR/sweep.csv: one row per run of a sweep that finished or failed, with the point, repeat and
// seed, the grid values, the status, the exit code and error, the sweep's wall time of the
// child, and every numeric entry of the run's summary.json "timings" and "metrics" (nested
// keys dotted, booleans as 0/1) under the column names timings.KEY and metrics.KEY.
#pragma once

#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "sweep/sweep_point_run.hpp"
#include "sweep/sweep_spec.hpp"

namespace conform::scenes {

struct SweepRow {
  const SweepPoint* point = nullptr;
  PointStatus status;
  std::uint64_t seed = 0;                 // the run's seed (summary.json), or the point's
  std::map<std::string, double> numbers;  // timings.* and metrics.*
  std::string units;                      // metrics.units when the scene gives it
};

struct SweepTable {
  std::vector<SweepRow> rows;        // finished or failed points, in point order
  std::vector<int> missing;          // points with neither a summary nor a recorded failure
  std::vector<std::string> columns;  // the numeric columns, in order
  std::optional<double> value(const SweepRow& row, const std::string& column) const;
};

/// Reads every point's folder.
SweepTable gather_table(const SweepSpec& spec, const std::filesystem::path& dir);
/// Writes DIR/sweep.csv (atomically) from the table.
void write_table(const SweepSpec& spec, const SweepTable& table, const std::filesystem::path& dir);

}  // namespace conform::scenes
