#include "render/plots.hpp"

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include "base/child_process.hpp"
#include "base/interrupt.hpp"
#include "render/render_frames.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

// A gnuplot string constant holding `s` as it is: single-quoted, where gnuplot substitutes no
// backquoted command and no escape (a quote is doubled). A line break would end the command:
// it becomes a space.
std::string quote(const std::string& s) {
  std::string out = "'";
  for (const char c : s) {
    if (c == '\'') out += '\'';
    out += c == '\n' || c == '\r' ? ' ' : c;
  }
  return out + "'";
}

// A text option of `p`: its quoted string, read as markup only when the plot says it is.
std::string text(const Plot& p, const std::string& s) {
  return quote(s) + (p.enhanced_text ? "" : " noenhanced");
}

// The y of a series as a gnuplot using-expression: the column, or the column times its scale
// (an empty field stays missing: column() of it is undefined, not 0).
std::string y_of(const PlotSeries& s) {
  if (s.y_scale == 1) return quote(s.y);
  std::ostringstream e;
  e.precision(17);
  e << "(column(" << quote(s.y) << ")*" << s.y_scale << ")";
  return e.str();
}

void write_axes(std::ostream& gp, const Plot& p) {
  gp << "set title " << text(p, p.title) << "\n"
     << "set xlabel " << text(p, p.xlabel) << "\n"
     << "set ylabel " << text(p, p.ylabel) << "\n"
     << (p.log_y ? "set logscale y\nset format y '%g'\n"
                 : "unset logscale y\nset format y '% h'\n");
  if (p.y_range.first < p.y_range.second)
    gp << "set yrange [" << p.y_range.first << ":" << p.y_range.second << "]\n";
  else
    gp << "set yrange [*:*]\n";
  if (p.x_tics.empty()) {
    gp << "set xtics autofreq\n";
  } else {
    gp << "set xtics (";
    for (std::size_t i = 0; i < p.x_tics.size(); ++i) gp << (i ? ", " : "") << p.x_tics[i];
    gp << ")\n";
  }
  gp << "unset arrow\nunset label\n";
  for (const PlotEvent& e : p.events) {
    gp << "set arrow from " << e.x << ", graph 0 to " << e.x
       << ", graph 1 nohead dashtype 2 lc rgb 'gray40'\n"
       << "set label " << text(p, e.label) << " at " << e.x
       << ", graph 0.03 offset 0.5, 0 left textcolor rgb 'gray30'\n";  // below the key
  }
  gp << "plot ";
  for (std::size_t i = 0; i < p.series.size(); ++i) {
    const auto& s = p.series[i];
    gp << (i ? ", \\\n     " : "") << quote(s.file) << " using " << quote(s.x) << ":" << y_of(s)
       << " with " << s.style << " lw 2 title " << text(p, s.title);
  }
  gp << "\n";
}

bool write_plot_script(const fs::path& dir, const Plot& plot, std::string& problem) {
  const fs::path script = dir / (plot.name + ".gp");
  std::ofstream gp(script);
  if (!gp) {
    problem = "cannot write " + script.string();
    return false;
  }
  const int panels = std::max<int>(1, static_cast<int>(plot.panels.size()));
  // `reset` first: the scripts run one after the other in one gnuplot (draw_plots).
  gp << "# Drawn by conform from the CSV files beside it: gnuplot " << plot.name << ".gp\n"
     << "reset\nset terminal pngcairo size " << (panels > 1 ? 600 * panels : 1000)
     << ",600 enhanced font 'sans,11'\n"
     << "set output " << quote(plot.name + ".png") << "\n"
     << "set datafile separator ','\n"
     << "set grid\nset key top left\n";
  if (plot.panels.empty()) {
    write_axes(gp, plot);
  } else {
    gp << "set multiplot layout 1," << panels << " title " << text(plot, plot.title) << "\n";
    for (const auto& p : plot.panels) write_axes(gp, p);
    gp << "unset multiplot\n";
  }
  gp << "unset output\n";  // the PNG is complete before the next script starts
  if (!gp) problem = "cannot write " + script.string();
  return bool(gp);
}

// Whether column `name` of the CSV file (written by RunOutput::Csv: numbers or empty fields)
// holds only 0 and empty fields; false when the file or the column cannot be read.
bool column_is_zero(const fs::path& file, const std::string& name) {
  std::ifstream in(file);
  std::string line, field;
  if (!std::getline(in, line)) return false;
  std::stringstream header(line);
  std::size_t index = 0;
  while (std::getline(header, field, ',') && field != name) ++index;
  if (field != name) return false;
  while (std::getline(in, line)) {
    std::stringstream row(line);
    for (std::size_t i = 0; i <= index; ++i)
      if (!std::getline(row, field, ',')) field.clear();
    if (!field.empty() && std::strtod(field.c_str(), nullptr) != 0.0) return false;
  }
  return true;
}

}  // namespace

std::vector<std::string> draw_plots(const fs::path& dir, const std::vector<Plot>& plots) {
  std::vector<std::string> problems(plots.size());
  std::vector<std::string> args = {"gnuplot"};
  for (std::size_t i = 0; i < plots.size(); ++i)
    if (write_plot_script(dir, plots[i], problems[i])) args.push_back(plots[i].name + ".gp");
  if (args.size() == 1) return problems;
  // One gnuplot for all: its start-up (fonts, cairo) is most of a small plot's cost.
  const fs::path log = fs::absolute(dir / "plots.log");
  ChildOptions options;
  options.log = log.string();
  options.dir = fs::absolute(dir).string();
  ChildProcess gnuplot(args, options);
  const bool ok = gnuplot.running() && gnuplot.wait() == 0;
  check_interrupt();
  // gnuplot stops at the first failing script: what came before it was drawn.
  for (std::size_t i = 0; i < plots.size(); ++i)
    if (problems[i].empty() && (!ok || !fs::exists(dir / (plots[i].name + ".png"))))
      problems[i] = "gnuplot failed (see plots.log in the output folder)";
  if (ok) fs::remove(log);
  return problems;
}

bool have_gnuplot() {
  return have_tool("gnuplot");
}

std::vector<std::string> drop_zero_series(const fs::path& dir, Plot& plot) {
  std::vector<std::string> notes;
  const auto zero = [&](const PlotSeries& s) {
    if (!column_is_zero(dir / s.file, s.y)) return false;
    notes.push_back(s.y + " is 0 at every row of " + s.file);
    return true;
  };
  std::erase_if(plot.series, zero);
  for (Plot& panel : plot.panels) std::erase_if(panel.series, zero);
  std::erase_if(plot.panels, [](const Plot& p) { return p.series.empty(); });
  return notes;
}

bool has_series(const Plot& plot) {
  return !plot.series.empty() || !plot.panels.empty();
}

}  // namespace conform::scenes
