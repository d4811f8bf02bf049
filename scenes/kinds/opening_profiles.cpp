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

OpeningProfiles::OpeningProfiles(int points, int snapshots, double from, int steps, double dt) {
  bins_.resize(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) bins_[static_cast<std::size_t>(i)] = double(i) / (points - 1);
  const double end_time = steps * dt;
  for (int k = 0; k < snapshots; ++k) {
    const double u = double(k + 1) / snapshots;
    const double t = from + (end_time - from) * u * u;
    snapshot_steps_.push_back(std::clamp(static_cast<int>(std::lround(t / dt)), 1, steps));
  }
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

void OpeningProfiles::add_plots(RunOutput& out, const std::string& scene,
                                const std::string& physics, const std::string& geometric,
                                const std::string& geometric_short) const {
  const std::vector<std::string> cols = columns();
  const std::string along = "position along the tear (0 = start, 1 = tip)";
  Plot side{"profiles", scene + ": gap-width profile along the tear over time", "", "", {}, {}};
  Plot left{"", physics, along, "gap width [m]", {}, {}};
  Plot right{"", geometric, along, "gap width [m]", {}, {}};
  char name[48];
  for (std::size_t k = 0; k < snap_times_.size(); ++k) {
    std::snprintf(name, sizeof name, "t = %.2f s", snap_times_[k]);
    left.series.push_back({"profiles.csv", "s", cols[1 + k], name, "lines"});
    right.series.push_back({"profiles.csv", "s", cols[1 + snap_times_.size() + k], name, "lines"});
  }
  side.panels = {left, right};
  out.add_plot(side);
  out.add_plot({"opening",
                scene + ": largest gap width",
                "time [s]",
                "largest gap width [m]",
                {{"metrics.csv", "t", "physics_max_opening", "physics", "lines"},
                 {"metrics.csv", "t", "geometric_max_opening", geometric_short, "lines"}},
                {}});
  out.add_plot({"area",
                scene + ": opened area",
                "time [s]",
                "opened area [m^2]",
                {{"metrics.csv", "t", "physics_area", "physics", "lines"},
                 {"metrics.csv", "t", "geometric_area", geometric_short, "lines"}},
                {}});
}

}  // namespace conform::scenes
