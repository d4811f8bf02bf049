#include "sweep/sweep_plots.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <sstream>

#include "kinds/scene.hpp"
#include "render/plots.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

std::vector<std::string> split_commas(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

bool numeric(const std::string& s, double& x) {
  char* end = nullptr;
  x = std::strtod(s.c_str(), &end);
  return end != s.c_str() && *end == '\0';
}

// Keys and values as literal gnuplot enhanced text that holds no character gnuplot's string
// syntax reads: markup (_ ^ { } & ~) escaped with a backslash, and quotes, backquotes (a command
// inside a double-quoted string), backslashes, $ ; @ and control characters (a line break would
// end the string and start a command) as the enhanced-text octal code \ooo. So the text is safe
// in a gnuplot string of either kind. gnuplot decodes \ooo only in text it reads as markup: a
// leading {} (an empty group) says that it is.
std::string literal(const std::string& s) {
  std::string out;
  bool coded = false;
  for (char c : s) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f || std::string("`\"'\\$;@").find(c) != std::string::npos) {
      char code[8];
      std::snprintf(code, sizeof code, "\\%03o", unsigned(u));
      out += code;
      coded = true;
      continue;
    }
    if (std::string("_^{}&~").find(c) != std::string::npos) out += '\\';
    out += c;
  }
  return coded ? "{}" + out : out;
}

std::string file_stem(const std::string& s) {
  std::string out;
  for (char c : s) out += std::isalnum(static_cast<unsigned char>(c)) ? c : '_';
  return out;
}

// A tic at each value of an axis of a few whole numbers (resolutions, substeps), so that gnuplot
// does not label 1.5 between 1 and 2; none (gnuplot's own) otherwise.
std::vector<double> whole_number_tics(const std::vector<std::string>& values) {
  std::vector<double> tics;
  for (const auto& value : values) {
    double v = 0;
    if (!numeric(value, v) || v != std::round(v)) return {};
    tics.push_back(v);
  }
  return tics.size() <= 20 ? tics : std::vector<double>{};
}

// One line: mean of the metric over the rows with the same x (the repeats).
using Line = std::map<double, std::pair<double, int>>;

}  // namespace

std::vector<std::string> plot_metrics(const SweepSpec& spec) {
  if (!spec.plot.empty()) return spec.plot;
  const SceneKind* kind = find_builtin(spec.kind);
  return split_commas(kind && kind->headline ? kind->headline : "");
}

namespace {

// The lines of `metric` against axis `x`: keyed by the other axes' values.
std::map<std::string, Line> lines_of(const SweepSpec& spec, const SweepTable& table, std::size_t x,
                                     const std::string& metric) {
  std::map<std::string, Line> lines;
  for (const auto& r : table.rows) {
    const auto y = table.value(r, "metrics." + metric);
    double xv = 0;
    if (!y || !numeric(r.point->values[x].second, xv)) continue;
    std::string others;
    for (std::size_t a = 0; a < r.point->values.size(); ++a)
      // Zipped axes move with x: they label points of one line, not lines.
      if (a != x && !(spec.axes[x].zipped && spec.axes[a].zipped))
        others += (others.empty() ? "" : ", ") + r.point->values[a].first + " = " +
                  r.point->values[a].second;
    auto& [sum, n] = lines[others.empty() ? "all runs" : others][xv];
    sum += *y;
    ++n;
  }
  return lines;
}

Plot sweep_plot(const SweepSpec& spec, const SweepTable& table, std::size_t x,
                const std::string& metric, const fs::path& plots_dir) {
  const std::string& key = spec.axes[x].key;
  Plot plot;
  plot.enhanced_text = true;  // keys and values are escaped as enhanced text (literal)
  plot.name = file_stem(metric) + "_vs_" + file_stem(key);
  std::string units;
  for (const auto& r : table.rows) units = units.empty() ? r.units : units;
  plot.title = literal(spec.kind + ": " + metric + " against " + key) +
               (units.empty() ? "" : "  {/*0.8 (" + literal(units) + ")}");
  plot.xlabel = literal(key);
  plot.ylabel = literal(metric) +
                (spec.repeat > 1 ? " (mean of " + std::to_string(spec.repeat) + " seeds)" : "");
  plot.x_tics = whole_number_tics(spec.axes[x].values);
  int n = 0;
  for (const auto& [title, line] : lines_of(spec, table, x, metric)) {
    const std::string data = "data/" + plot.name + "_" + std::to_string(n++) + ".csv";
    std::ofstream out(plots_dir / data);
    out << "x,y\n";
    char buf[64];
    for (const auto& [xv, sum_n] : line) {
      std::snprintf(buf, sizeof buf, "%.9g,%.9g\n", xv, sum_n.first / sum_n.second);
      out << buf;
    }
    plot.series.push_back({data, "x", "y", literal(title), "linespoints"});
  }
  return plot;
}

}  // namespace

SweepPlots draw_sweep_plots(const SweepSpec& spec, const SweepTable& table, const fs::path& dir) {
  SweepPlots result;
  const fs::path plots_dir = dir / "plots";
  std::error_code ec;
  fs::create_directories(plots_dir / "data", ec);
  if (ec) {
    result.problems.push_back("cannot create " + (plots_dir / "data").string());
    return result;
  }
  std::vector<Plot> plots;
  for (const auto& metric : plot_metrics(spec)) {
    if (!table.rows.empty() && std::find(table.columns.begin(), table.columns.end(),
                                         "metrics." + metric) == table.columns.end()) {
      std::string known;
      for (const auto& c : table.columns)
        if (c.rfind("metrics.", 0) == 0) known += (known.empty() ? "" : ", ") + c.substr(8);
      if (!known.empty()) {
        result.problems.push_back(metric + ": not a numeric metric of these runs (known: " + known +
                                  ")");
        continue;
      }
    }
    for (std::size_t x = 0; x < spec.axes.size(); ++x) {
      double v = 0;
      int numbers = 0;
      for (const auto& value : spec.axes[x].values) numbers += numeric(value, v);
      if (numbers < 2) continue;  // a key of words, or one value: only a line label
      Plot plot = sweep_plot(spec, table, x, metric, plots_dir);
      if (plot.series.empty())
        result.problems.push_back(plot.name + ": no finished run has " + metric);
      else
        plots.push_back(std::move(plot));
    }
  }
  // All in one gnuplot process (draw_plots): its start-up is most of a small plot's cost.
  std::vector<std::string> problems(
      plots.size(), "gnuplot is not installed (scripts/deps.sh installs gnuplot-nox)");
  if (!plots.empty() && have_gnuplot()) problems = draw_plots(plots_dir, plots);
  for (std::size_t i = 0; i < plots.size(); ++i)
    if (problems[i].empty())
      result.drawn.push_back((plots_dir / (plots[i].name + ".png")).string());
    else
      result.problems.push_back(plots[i].name + ": " + problems[i]);
  return result;
}

}  // namespace conform::scenes
