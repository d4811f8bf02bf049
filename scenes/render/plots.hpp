// Line plots of a run's CSV files, drawn by gnuplot into PNGs (the script beside each). A run's
// plots (RunOutput) and a sweep's (sweep_plots.hpp) are drawn through draw_plots.
#pragma once

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace conform::scenes {

/// One line of a gnuplot figure: a CSV column against another. An empty field is a value that
/// does not exist at that row (e.g. the hand piece before the cut): the line has a gap there.
struct PlotSeries {
  PlotSeries() = default;
  PlotSeries(std::string file_, std::string x_, std::string y_, std::string title_,
             std::string style_ = "lines", double y_scale_ = 1)
      : file(std::move(file_)),
        x(std::move(x_)),
        y(std::move(y_)),
        title(std::move(title_)),
        style(std::move(style_)),
        y_scale(y_scale_) {}

  std::string file = "metrics.csv";  // relative to the run folder
  std::string x, y;                  // column names
  std::string title;
  std::string style = "lines";
  double y_scale = 1;  // y is drawn times this (1000: metres drawn in millimetres)
};

/// A vertical dashed line at x, labelled: an event of the run (a cut, a stroke's end, a flex).
struct PlotEvent {
  double x = 0;
  std::string label;
};

struct Plot {
  Plot() = default;
  Plot(std::string name_, std::string title_, std::string xlabel_, std::string ylabel_,
       std::vector<PlotSeries> series_, std::vector<Plot> panels_ = {})
      : name(std::move(name_)),
        title(std::move(title_)),
        xlabel(std::move(xlabel_)),
        ylabel(std::move(ylabel_)),
        series(std::move(series_)),
        panels(std::move(panels_)) {}

  std::string name;  // file stem: NAME.png (and NAME.gp, the script that drew it)
  std::string title, xlabel, ylabel;
  std::vector<PlotSeries> series;
  /// Several panels side by side (multiplot), each with its own series; overrides `series`.
  std::vector<Plot> panels;
  bool log_y = false;
  /// The y axis from first to second (both in the drawn unit, after y_scale); equal: autoscale.
  std::pair<double, double> y_range{0, 0};
  /// The x tics, when x takes a few chosen values (a sweep's resolutions): one tic at each, so
  /// that whole numbers are not labelled 1.5; empty: gnuplot's own.
  std::vector<double> x_tics;
  std::vector<PlotEvent> events;
  /// Titles, labels and keys are shown as written (w_max is not w with a subscript), unless the
  /// text is gnuplot's enhanced markup already (the sweep's plots escape their keys as such).
  bool enhanced_text = false;
};

/// Draws each plot into dir/NAME.png (its script kept as dir/NAME.gp; series files relative to
/// `dir`), all in one gnuplot process; returns each plot's problem ("" when drawn). Every title,
/// label and file name is a single-quoted gnuplot string (no backquote substitution), and
/// gnuplot is run from its argument vector, not through a shell.
std::vector<std::string> draw_plots(const std::filesystem::path& dir,
                                    const std::vector<Plot>& plots);
/// Whether gnuplot is on the PATH.
bool have_gnuplot();

/// Removes from `plot` (and its panels) every series whose column is 0 or empty at every row
/// of its file, and the panels left without one: a flat line at 0 says nothing a sentence
/// cannot. Returns a sentence for each series removed ("seam_gap is 0 at every row of
/// metrics.csv"), for the run's summary. A file or column that cannot be read is kept (gnuplot
/// then reports it).
std::vector<std::string> drop_zero_series(const std::filesystem::path& dir, Plot& plot);

/// Whether anything is left to draw in `plot`.
bool has_series(const Plot& plot);

}  // namespace conform::scenes
