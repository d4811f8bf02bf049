// The ground a scene's severed pieces fall onto, and their release from skinning. A piece that a
// cut severs from the body is released (bullet::SkinnedSoftBody::release_piece), keeps its
// volume when it is closed (a capped cut) and falls under gravity onto a static ground, with
// which only released pieces collide: the skinned body plays its animation, whose feet may
// dip below any floor, undisturbed.
#pragma once

#include <limits>
#include <memory>
#include <vector>

#include "base/scene_config.hpp"
#include "conform/bullet/skinned_soft_body.hpp"
#include "kinds/soft_scene.hpp"
#include "render/plots.hpp"

class btBoxShape;
class btRigidBody;

namespace conform::scenes {

/// `ground`: true / false, or { "enabled": …, "height": m (the top's y) }.
struct GroundSettings {
  bool enabled = false;
  double height = std::numeric_limits<double>::quiet_NaN();  // m; NaN: the scene's default
};
GroundSettings read_ground(Reader& root, const GroundSettings& defaults);
/// summary.json's "ground": enabled, and its height_m when enabled.
Json ground_summary(const GroundSettings& ground);

/// `cut.release` (the severed pieces fall) and `cut.volume_modulus` (Pa, kept by closed pieces).
struct SeverSettings {
  bool release = false;
  double volume_modulus = 1e5;  // near-incompressible tissue inside the skin
};
SeverSettings read_sever(Reader& cut, const SeverSettings& defaults);

/// A static box whose top is at `height`, `size` (m, the model's scale) wide on each side of
/// `centre` and 2 size thick. It sets the soft bodies' contact grid (Bullet's sparse SDF) to size /
/// 100: at Bullet's 0.25 m a 5 cm piece sinks into a box
/// (tests/plugin/plugin_release_test.cpp).
class Ground {
 public:
  static constexpr int kGroup = 1 << 6;  // broadphase group: meets only released pieces
  Ground(SoftWorld& world, double height, const Eigen::Vector3d& centre, double size);
  ~Ground();
  Ground(const Ground&) = delete;
  Ground& operator=(const Ground&) = delete;
  double height() const { return height_; }
  /// Refines the soft bodies' contact grid for a released piece of `piece_size` (m).
  void fit_contact_grid(double piece_size);

 private:
  SoftWorld& world_;
  double height_;
  std::unique_ptr<btBoxShape> shape_;
  std::unique_ptr<btRigidBody> body_;
};

/// The pieces released after a cut, and how they fall.
class FallingPieces {
 public:
  /// Before the cut: which piece each vertex is in.
  void before_cut(const bullet::SkinnedSoftBody& body);
  /// After it: of each piece the cut split, every part but the one with the most vertices (the
  /// body the cut was made on) is released, with `volume_modulus` when it is closed (0 when
  /// open), and meets `ground`.
  Json release_severed(bullet::SkinnedSoftBody& body, double volume_modulus, Ground* ground);
  /// After each step: the released pieces' lowest node above the ground, speed and volume.
  void measure(const bullet::SkinnedSoftBody& body, const Ground* ground);
  /// The lowest released node's height above the ground (or its y without one), m; NaN before
  /// any release.
  double lowest() const { return lowest_; }
  bool any() const { return !pieces_.empty(); }
  Json summary() const;

 private:
  struct Fallen {
    bullet::PieceId id;
    std::int32_t nodes = 0;
    double volume_at_release = 0, volume = 0;  // m³ (0: open)
    double com_y_at_release = 0, com_y = 0;    // m
    double speed = 0, lowest = 0;              // m/s, m
  };
  static void measure_one(const btSoftBody& body, Fallen& f, double ground);
  std::vector<bullet::PieceId> piece_before_;  // per vertex, before the cut
  std::vector<Fallen> pieces_;
  double lowest_ = std::numeric_limits<double>::quiet_NaN();
  double ground_ = std::numeric_limits<double>::quiet_NaN();
};

/// The plot of metrics.csv's released_lowest_m over time, the cut (at `cut_at`, s) marked.
Plot falling_plot(const std::string& scene, bool ground, double cut_at);

}  // namespace conform::scenes
