#include "kinds/opening_profiles.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace conform::scenes {

Profile physical_profile(const bullet::SkinnedSoftBody& body) {
  const mesh::Tear* tear = body.tear();
  if (!tear || tear->path_length() < 2) return {};
  const mesh::SkinnedMesh& m = body.mesh();
  return measure_profile(
      tear->left_border(), tear->right_border(),
      [&body](std::int32_t v) { return body.position(v); },
      [&m](std::int32_t v) { return Eigen::Vector3d(m.rest.col(v)); });
}

Lips tear_lips(const mesh::Tear* tear) {
  if (!tear || tear->path_length() < 2) return {};
  return {tear->left_border(), tear->right_border()};
}

ComparisonKeys read_comparison_keys(Reader& root) {
  ComparisonKeys k;
  Reader geo = root.object("geometric");
  k.amount = geo.number("amount", k.amount, 0, 1);
  geo.finish();
  Reader prof = root.object("profiles");
  k.snapshots = prof.integer("snapshots", k.snapshots, 1, 100);
  k.points = prof.integer("points", k.points, 3, 10000);
  prof.finish();
  return k;
}

std::string gap_caption(const Profile& profile) {
  if (profile.s.empty()) return "not torn yet";
  char buf[48];
  std::snprintf(buf, sizeof buf, "largest gap %.2f mm", 1e3 * profile.max);
  return buf;
}

OpeningProfiles::OpeningProfiles(int points, int snapshots, double from, int steps, double dt) {
  bins_.resize(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) bins_[static_cast<std::size_t>(i)] = double(i) / (points - 1);
  const double end_time = steps * dt;
  for (int k = 0; k < snapshots; ++k) {
    const double u = double(k + 1) / snapshots;
    const double t = from + (end_time - from) * u * u;
    snapshot_steps_.push_back(std::clamp(static_cast<int>(std::lround(t / dt)), 1, steps));
  }
  // A short run can round two snapshots to one step: it is kept once (one column per step).
  snapshot_steps_.erase(std::unique(snapshot_steps_.begin(), snapshot_steps_.end()),
                        snapshot_steps_.end());
}

void OpeningProfiles::open_history(RunOutput& out) {
  history_.emplace(
      out.open_csv("profile_history.csv", {"t", "s", "physics_width", "geometric_width"}));
}

void OpeningProfiles::history_row(double t, const Profile& physics, const Profile& geometric) {
  if (!history_) return;
  const auto pw = resample(physics, bins_), gw = resample(geometric, bins_);
  for (std::size_t i = 0; i < bins_.size(); ++i) {
    const double h[] = {t, bins_[i], pw[i], gw[i]};
    history_->row(h);
  }
}

void OpeningProfiles::snapshot(int step, double t, const Profile& physics,
                               const Profile& geometric) {
  for (const int s : snapshot_steps_)
    if (s == step) {
      snap_times_.push_back(t);
      snap_physics_.push_back(resample(physics, bins_));
      snap_geometric_.push_back(resample(geometric, bins_));
    }
}

std::vector<std::string> OpeningProfiles::columns() const {
  std::vector<std::string> cols{"s"};
  char name[48];
  for (const double t : snap_times_) {
    std::snprintf(name, sizeof name, "physics_%.2fs", t);
    cols.push_back(name);
  }
  for (const double t : snap_times_) {
    std::snprintf(name, sizeof name, "geometric_%.2fs", t);
    cols.push_back(name);
  }
  return cols;
}

void OpeningProfiles::write(RunOutput& out) const {
  RunOutput::Csv profiles = out.open_csv("profiles.csv", columns());
  for (std::size_t i = 0; i < bins_.size(); ++i) {
    std::vector<double> row{bins_[i]};
    for (const auto& p : snap_physics_) row.push_back(p[i]);
    for (const auto& g : snap_geometric_) row.push_back(g[i]);
    profiles.row(row);
  }
}

namespace {

double largest(const std::vector<double>& w) {
  return w.empty() ? 0.0 : *std::max_element(w.begin(), w.end());
}

// The final profiles of both runs on the same axes, in mm, titled with their ratio: the
// comparison the scenes exist for.
Plot final_overlay(const std::string& scene, const std::string& physics_column,
                   const std::string& geometric_column, double physics_max, double geometric_max,
                   double t, const std::string& geometric) {
  char title[200];
  std::snprintf(title, sizeof title,
                "%s: final gap-width profiles at t = %.2f s (largest: physics %.2f mm, "
                "geometric %.2f mm, ratio %.2f)",
                scene.c_str(), t, 1e3 * physics_max, 1e3 * geometric_max,
                geometric_max > 0 ? physics_max / geometric_max : 0.0);
  return {"final_profiles",
          title,
          "position along the tear (0 = start, 1 = tip)",
          "gap width [mm]",
          {{"profiles.csv", "s", physics_column, "physics", "lines", 1e3},
           {"profiles.csv", "s", geometric_column, geometric, "lines", 1e3}}};
}

// metrics.csv's physics_QUANTITY and geometric_QUANTITY over time, scaled (to mm, mm²), with the
// run's events marked.
Plot over_time(const std::string& name, const std::string& title, const std::string& ylabel,
               const std::string& quantity, double scale, const std::string& geometric,
               const std::vector<PlotEvent>& events) {
  Plot p{name,
         title,
         "time [s]",
         ylabel,
         {{"metrics.csv", "t", "physics_" + quantity, "physics", "lines", scale},
          {"metrics.csv", "t", "geometric_" + quantity, geometric, "lines", scale}}};
  p.events = events;
  return p;
}

}  // namespace

void OpeningProfiles::add_plots(RunOutput& out, const Labels& labels,
                                const std::vector<PlotEvent>& events) const {
  const std::vector<std::string> cols = columns();
  const std::size_t n = snap_times_.size();
  const std::string along = "position along the tear (0 = start, 1 = tip)";
  if (n > 0)
    out.add_plot(final_overlay(labels.scene, cols[n], cols[2 * n], largest(snap_physics_.back()),
                               largest(snap_geometric_.back()), snap_times_.back(),
                               labels.geometric));
  // Both panels on one scale (in mm), so that their heights compare at a glance.
  double top = 0;
  for (std::size_t k = 0; k < n; ++k)
    top = std::max({top, largest(snap_physics_[k]), largest(snap_geometric_[k])});
  Plot side{"profiles", labels.scene + ": gap-width profile along the tear over time", "", "", {}};
  Plot left{"", labels.physics, along, "gap width [mm]", {}};
  Plot right{"", labels.geometric, along, "gap width [mm]", {}};
  char name[48];
  for (std::size_t k = 0; k < n; ++k) {
    std::snprintf(name, sizeof name, "t = %.2f s", snap_times_[k]);
    left.series.push_back({"profiles.csv", "s", cols[1 + k], name, "lines", 1e3});
    right.series.push_back({"profiles.csv", "s", cols[1 + n + k], name, "lines", 1e3});
  }
  left.y_range = right.y_range = {0, 1.05e3 * top};
  side.panels = {left, right};
  out.add_plot(side);
  const std::string& geo = labels.geometric_short;
  out.add_plot(over_time("opening", labels.scene + ": largest gap width", "largest gap width [mm]",
                         "max_opening", 1e3, geo, events));
  out.add_plot(over_time("area", labels.scene + ": opened area", "opened area [mm²]", "area", 1e6,
                         geo, events));
}

}  // namespace conform::scenes
