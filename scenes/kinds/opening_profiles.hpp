// A tear's opening, physical against geometric, over a run: the gap-width profiles of both
// along the tear (soft_scene.hpp's Profile) resampled at fixed positions, a history of them at
// every metrics row (profile_history.csv), snapshots at chosen steps side by side
// (profiles.csv) and the plots of both (profiles, largest opening, opened area). Used by the
// scenes that run a geometric copy of their tear (geometric_tear.hpp) beside the physical one:
// tear-opening and character.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "conform/bullet/skinned_soft_body.hpp"
#include "kinds/run_output.hpp"
#include "kinds/soft_scene.hpp"

namespace conform::scenes {

/// The physical tear's profile now (empty before the body's tear has two points).
Profile physical_profile(const bullet::SkinnedSoftBody& body);
/// A tear's two borders, the wound the pictures aim at (none before the tear began).
Lips tear_lips(const mesh::Tear* tear);
/// The keys of a scene that compares its tear with a geometric copy: geometric.amount (how far
/// the copy is opened, in the scene's own unit), profiles.snapshots and profiles.points.
struct ComparisonKeys {
  double amount = 0.01;
  int snapshots = 6, points = 41;
};
ComparisonKeys read_comparison_keys(Reader& root);

/// A picture panel's caption: the profile's largest gap in mm ("largest gap 13.24 mm"), or
/// "not torn yet".
std::string gap_caption(const Profile& profile);

class OpeningProfiles {
 public:
  /// `points` positions along the tear (0 = start, 1 = tip); `snapshots` steps from `from`
  /// (s, the tear's start) to the run's end (`steps` of `dt`), denser early on.
  OpeningProfiles(int points, int snapshots, double from, int steps, double dt);

  /// Opens profile_history.csv (t, s, physics_width, geometric_width).
  void open_history(RunOutput& out);
  /// A metrics row's profiles into the history (once the tear has begun).
  void history_row(double t, const Profile& physics, const Profile& geometric);
  /// Keeps both profiles when `step` is a snapshot step.
  void snapshot(int step, double t, const Profile& physics, const Profile& geometric);
  /// profiles.csv: s, then one column per snapshot for each run.
  void write(RunOutput& out) const;
  /// What the plots call things: `scene` starts their titles, `physics` and `geometric` name
  /// the runs in the profile plots, `geometric_short` in the plots over time.
  struct Labels {
    std::string scene, physics, geometric, geometric_short;
  };
  /// The plots, in mm: the final profiles of both runs overlaid with their ratio
  /// (final_profiles), the profiles over time side by side on one scale (profiles), and the
  /// largest gap and the opened area over time with the run's `events` marked (opening, area).
  void add_plots(RunOutput& out, const Labels& labels, const std::vector<PlotEvent>& events) const;

 private:
  std::vector<std::string> columns() const;

  std::vector<double> bins_;         // normalized positions along the tear where profiles are kept
  std::vector<int> snapshot_steps_;  // steps whose profiles go into profiles.csv
  std::vector<std::vector<double>> snap_physics_, snap_geometric_;
  std::vector<double> snap_times_;
  std::optional<RunOutput::Csv> history_;
};

}  // namespace conform::scenes
