// The plots of a sweep: each chosen metric against each grid key that has at least two
// numeric values, one line per combination of the other keys' values (repeats averaged; keys
// zipped with the plotted one move along its line),
// drawn by one gnuplot through draw_plots (run_output.hpp) into DIR/plots/METRIC_vs_KEY.png, with
// the data of every line in DIR/plots/data/.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "sweep/sweep_table.hpp"

namespace conform::scenes {

struct SweepPlots {
  std::vector<std::string> drawn;     // PNG paths
  std::vector<std::string> problems;  // why a plot was not drawn
};

/// The metrics to plot: spec.plot (names of summary.json "metrics" keys, dotted), or when
/// empty the scene kind's headline metrics.
std::vector<std::string> plot_metrics(const SweepSpec& spec);

/// Draws every plot it can; a metric no finished run has (a misspelt --plot) is a problem
/// that lists the metrics the runs do have.
SweepPlots draw_sweep_plots(const SweepSpec& spec, const SweepTable& table,
                            const std::filesystem::path& dir);

}  // namespace conform::scenes
