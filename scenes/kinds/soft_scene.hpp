// Shared pieces of the soft-body scenes (tear-opening, cut, drill, character): a
// btSoftRigidDynamicsWorld with the Conform plugin attached, the "material" section of a scene
// file, scalpel paths, the arm's pose and tear-profile measurements.
#pragma once

#include <memory>
#include <vector>

#include "conform/bullet/plugin.hpp"
#include "conform/bullet/soft_world.hpp"
#include "conform/mesh/tear.hpp"
#include "kinds/run_output.hpp"

namespace conform::scenes {

/// The plugin's soft world (conform/bullet/soft_world.hpp) with the scene's settings and the
/// Conform plugin attached.
struct SoftWorld : bullet::SoftWorld {
  std::unique_ptr<bullet::Plugin> plugin;
  double dt = 1.0 / 60;
  int substeps = 1;
  long long steps_done = 0;

  explicit SoftWorld(const CommonSettings& c);
  ~SoftWorld() { plugin.reset(); }  // the plugin's bodies leave the world first
  /// One step of c.dt in c.substeps fixed substeps. A simulation gone non-finite (the plugin's
  /// bullet::NonFiniteState) ends it with an error naming the scene's step as well.
  void step();
};

/// Distances of nodes from their skinned targets.
struct OffsetStats {
  double mean = 0, max = 0;
  long n = 0;
};
/// Over `vertices` (all when empty), leaving out the released pieces' (no longer skinned).
OffsetStats offsets(const bullet::SkinnedSoftBody& body, const std::vector<std::int32_t>& vertices);
/// Every node position finite.
bool finite_nodes(const bullet::SkinnedSoftBody& body);

/// Reads the "material" object (every key of bullet::Material), with scene-specific defaults.
bullet::Material read_material(Reader& root, const bullet::Material& defaults);

/// A straight scalpel stroke: the blade's ends are offsets from a point moving from `from` to
/// `to` between `at` and `at + duration`, sampled `samples` times.
struct Stroke {
  double at = 0, duration = 0.5;
  int samples = 40;
  Eigen::Vector3d from, to, blade_a, blade_b;
  mesh::ScalpelSample sample(int i) const;
  double time(int i) const { return at + duration * i / std::max(1, samples - 1); }
};
Stroke read_stroke(Reader& r, const Stroke& defaults);

/// Gap widths along a tear: pairs of the two borders, at their rest-space arc position.
struct Profile {
  std::vector<double> s;  // rest-space arc length from the tear's start, normalized to [0, 1]
  std::vector<double> w;  // distance between the two borders' copies, m
  double length = 0;      // rest-space length, m
  double max = 0;         // largest width, m
  double area = 0;        // area enclosed by the two borders, m² (|vector area|)
  double r2 = 0;          // R² of the best elliptical profile w_max·sqrt(1 − (2s − 1)²)
  double fit_max = 0;     // that ellipse's w_max
};

/// Measures a tear's opening from its borders (left/right vertex chains of equal length),
/// with `position(v)` the current and `rest(v)` the rest position of a vertex.
template <class Pos, class Rest>
Profile measure_profile(const std::vector<std::int32_t>& left,
                        const std::vector<std::int32_t>& right, Pos&& position, Rest&& rest);
/// Linear interpolation of the profile at normalized positions `at` (0 outside).
std::vector<double> resample(const Profile& p, const std::vector<double>& at);
/// Fills r2 and fit_max.
void fit_ellipse(Profile& p);

template <class Pos, class Rest>
Profile measure_profile(const std::vector<std::int32_t>& left,
                        const std::vector<std::int32_t>& right, Pos&& position, Rest&& rest) {
  Profile p;
  const std::size_t n = std::min(left.size(), right.size());
  if (n < 2) return p;
  double arc = 0;
  Eigen::Vector3d vector_area = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> loop;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) arc += (rest(right[i]) - rest(right[i - 1])).norm();
    p.s.push_back(arc);
    const Eigen::Vector3d l = position(left[i]), r = position(right[i]);
    p.w.push_back((l - r).norm());
    p.max = std::max(p.max, p.w.back());
    loop.push_back(r);
  }
  for (std::size_t i = n; i-- > 0;) loop.push_back(position(left[i]));
  for (std::size_t i = 0; i < loop.size(); ++i)
    vector_area += loop[i].cross(loop[(i + 1) % loop.size()]);
  p.area = 0.5 * vector_area.norm();
  p.length = arc;
  if (arc > 0)
    for (double& s : p.s) s /= arc;
  fit_ellipse(p);
  return p;
}

}  // namespace conform::scenes
