// The character scene's edits on a user's own rigged model: a cut, a tear and a drill placed
// in the model's rest (bind-pose) bounding box, carried to the animated pose by one bone, and
// applied to the Bullet soft body while the animation plays; and the gap across the seams
// that the import's weld closed.
//
// Placement (scene keys, so that the edits fit any model without knowing its units), in the
// bind pose (the model as its file shows it, `conform info`'s bind-pose bounds): a point is
// given as fractions of the bind pose's bounding box, p = lo + f ∘ (hi − lo); an offset (a
// blade end relative to its stroke point) as fractions of the box's size, d = f ∘ (hi − lo);
// a length (the drill's radius) as a fraction of the box's diagonal; a direction (the cut's
// normal) in the bind pose's axes. At the moment of the edit, bind-pose points are moved by
// one bone b from its bind pose to the body's last pose, V_b(t) V_b(bind)⁻¹ with V_b = G_j B_b
// its skinning versor (`bone`, or by default the bone weighing most on the bind-pose vertex
// nearest the edit's point), so the edit lands where that part of the body is now.
#pragma once

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "base/scene_config.hpp"
#include "conform/bullet/skinned_soft_body.hpp"
#include "kinds/falling_pieces.hpp"
#include "kinds/geometric_tear.hpp"
#include "kinds/skin_frame.hpp"

namespace conform::scenes {

/// The model in its bind pose: the frame of every placement key (its bounding box), and each
/// vertex's dominant bone.
struct BindPose {
  Eigen::Matrix3Xd positions;
  std::vector<mesh::Face> faces;
  std::vector<std::int32_t> dominant_bone;  // per vertex: the bone of its largest weight
  Eigen::Vector3d lo = Eigen::Vector3d::Zero(), hi = Eigen::Vector3d::Zero();
  /// From an imported mesh, whose `current` positions are the bind pose.
  explicit BindPose(const mesh::SkinnedMesh& mesh);
  Eigen::Vector3d point(const Eigen::Vector3d& f) const { return lo + f.cwiseProduct(hi - lo); }
  Eigen::Vector3d offset(const Eigen::Vector3d& f) const { return f.cwiseProduct(hi - lo); }
  double diagonal() const { return (hi - lo).norm(); }
  /// The dominant bone of the vertex nearest `p`.
  std::int32_t bone_near(const Eigen::Vector3d& p) const;
};

/// Moves bind-pose points and directions with one bone from its bind pose to the body's last
/// pose (and the body's world transform).
class BoneCarrier {
 public:
  /// `bone` indexes the body's skeleton's bones; −1: the dominant bone of the bind-pose
  /// vertex nearest `near`.
  BoneCarrier(const bullet::SkinnedSoftBody& body, const BindPose& bind, std::int32_t bone,
              const Eigen::Vector3d& near);
  Eigen::Vector3d point(const Eigen::Vector3d& bind) const;
  /// The unit direction that `direction` at `at` becomes.
  Eigen::Vector3d direction(const Eigen::Vector3d& at, const Eigen::Vector3d& direction) const;
  /// The versor's uniform scale (lengths are multiplied by it).
  double scale() const;
  const std::string& bone_name() const;

 private:
  skin::Versor versor() const;  // the bone's skinning versor at the body's last pose
  const bullet::SkinnedSoftBody& body_;
  std::int32_t bone_ = 0;
  skin::Versor from_bind_;  // V_b(bind)⁻¹
};

struct CutEdit {
  bool enabled = true;
  double at = 0.3;  // s
  std::string bone;
  bool on_limb = true;  // aimed at a limb (edit_placement.hpp), else in the box
  double along = 0.85;  // on the limb: where its section is cut, a fraction of its length
  Eigen::Vector3d point{0.68, 0.39, 0.305};  // in the box: box fractions
  Eigen::Vector3d normal{1, 0, -0.625};      // in the box: rest space
  bool cap = true;
  /// Which sections of the plane's meeting with the body are cut (mesh/cut_region.hpp):
  /// `nearest` the one nearest `seed` (a limb, not every limb the plane crosses), else all.
  enum class Region { everywhere, nearest } region = Region::nearest;
  Eigen::Vector3d seed{0.68, 0.39, 0.305};  // box fractions (cut.seed, by default `point`)
  SeverSettings sever{true, 1e5};           // cut.release, cut.volume_modulus (Pa)
};
struct TearEdit {
  bool enabled = true;
  double at = 0.5, duration = 0.4;  // s
  int samples = 12;
  std::string bone;
  bool on_limb = true;
  double along = 0.2;  // on the limb: where the stroke starts, a fraction of its length
  double length = 0;   // on the limb: the stroke's length, m (0: 40 % of the limb's)
  bool outer = true;   // on the limb: its side away from the model's centre, or toward it
  double depth = 0.5;  // on the limb: the blade's reach either side of the skin, of its radius
  Eigen::Vector3d from{0.1, 0.75, 1.0}, to{0.3, 0.75, 1.0};  // in the box: box fractions
  Eigen::Vector3d blade_a{0, 0, 0.3}, blade_b{0, 0, -0.45};  // in the box: offsets
  double time(int i) const { return at + duration * i / std::max(1, samples - 1); }
};
struct DrillEdit {
  bool enabled = true;
  double at = 1.1;  // s
  std::string bone;
  bool on_limb = true;
  double along = 0.5;                                          // on the limb
  Eigen::Vector3d tip{0.6, 0.2, 0.68}, base{-0.2, 0.2, 0.68};  // in the box: box fractions
  double limb_radius = 0.3;  // on the limb: the drill's radius, of the limb's radius
  double radius = 0.03;      // in the box: of the box's diagonal
  bool tube = true;
};

/// An edit's bind-pose geometry, and the bone that carries each part of it to the body's pose.
struct PlacedCut {
  Eigen::Vector3d point, normal, seed;
  std::int32_t bone = -1;  // −1: the dominant bone of the bind-pose vertex nearest `point`
  std::string limb;        // the aimed limb's root bone ("" in the box)
  SkinSection section;     // on a limb: the section cut, held by the skin (else empty)
};
struct PlacedTear {
  std::vector<Eigen::Vector3d> blade_a, blade_b;  // per sample (in the box)
  std::vector<std::int32_t> bone;                 // per sample, as PlacedCut::bone (in the box)
  std::vector<SkinAnchor> anchors;                // per sample (on a limb)
  std::string limb;
};
struct PlacedDrill {
  Eigen::Vector3d tip, base;
  double radius = 0;  // bind-pose units
  std::int32_t bone = -1;
  std::string limb;
  SkinSection section;  // on a limb: the section drilled through, held by the skin
  double reach = 0;     // on a limb: from the section's centre to either end, bind-pose units
};

/// The "cut", "tear" and "drill" objects of a character scene (defaults placed on huesitos.fbx).
CutEdit read_cut(Reader& root);
TearEdit read_tear(Reader& root);
DrillEdit read_drill(Reader& root);

/// The cut at the body's last pose; its summary entry ("status": "cut" or "missed": a plane
/// placed for another model may miss the user's; the run goes on).
nlohmann::json apply_cut(bullet::SkinnedSoftBody& body, const BindPose& bind, const PlacedCut& at,
                         const CutEdit& edit);

/// The tear, sample by sample as the simulated time passes its sample times.
class TearRun {
 public:
  TearRun(const TearEdit& edit, PlacedTear at, const BindPose& bind)
      : edit_(edit), at_(std::move(at)), bind_(bind) {}
  /// Advances every sample whose time is ≤ t (at the body's last pose), on the body and, when
  /// given, the same sample on its geometric copy (posed as the body's last pose).
  void advance(bullet::SkinnedSoftBody& body, double t, GeometricTear* copy = nullptr);
  bool started() const { return next_ > 0; }
  bool done() const { return next_ >= edit_.samples; }
  /// Its summary entry (samples, steps that extended the tear, length, message).
  nlohmann::json summary(const bullet::SkinnedSoftBody& body) const;

 private:
  mesh::ScalpelSample sample(const bullet::SkinnedSoftBody& body, double t);
  mesh::ScalpelSample copy_sample(const GeometricTear& copy, double t) const;
  const TearEdit edit_;
  const PlacedTear at_;
  const BindPose& bind_;
  int next_ = 0, extended_ = 0;
  // The samples after the first that left the tear as it was, with the tear's reason.
  std::vector<std::pair<int, std::string>> waits_;
  double tip_to_blade_ = -1;  // the tip's distance from the last sample's blade, m
  std::string bone_;
};

/// The drill at the body's last pose; its summary entry, with the removed area per hole against
/// πr² ("status": "drilled" or "missed").
/// The drill of a placement on a limb through its section `s` (as the skin holds it).
mesh::DrillTool drill_through(const PlacedDrill& at, const Section& s);

nlohmann::json apply_drill(bullet::SkinnedSoftBody& body, const BindPose& bind,
                           const PlacedDrill& at, const DrillEdit& edit);

/// The seams of the file: rest positions shared by several of its vertices within one
/// connected piece of skin, and the body's vertices that stand for them (one when the weld
/// joined them). The gap at a seam is the largest distance between those vertices now; welded
/// seams stay at zero by construction, seams left open (weights that differ, no weld) can open.
/// One piece of skin: file vertices joined by faces, by a shared rest position within one mesh
/// of the file (the importer splits a surface's vertices where their normals or texture
/// coordinates differ), or by the weld. Separate objects that touch (two boxes sharing a corner,
/// each on its own mesh and bone) are not seams.
class SeamGap {
 public:
  /// `file_rest`, `file_faces`: the mesh as the file gives it (before welding); `mesh_of`: the
  /// file mesh of each vertex; `vertex_map`: file vertex → body vertex (the weld's; identity
  /// when empty).
  SeamGap(const Eigen::Matrix3Xd& file_rest, std::span<const mesh::Face> file_faces,
          std::span<const std::int32_t> mesh_of, std::span<const std::int32_t> vertex_map);
  /// The largest gap now (vertices that left Bullet, e.g. drilled out, aside), in the
  /// body's units (metres in the character scene).
  double measure(const bullet::SkinnedSoftBody& body) const;
  std::int32_t positions() const { return static_cast<std::int32_t>(starts_.size()) - 1; }
  std::int32_t file_vertices() const { return file_vertices_; }
  /// Seam positions still held by more than one body vertex.
  std::int32_t open_positions() const { return open_; }
  /// Rest positions shared by separate pieces of skin (not measured as seams).
  std::int32_t touching_positions() const { return touching_; }

 private:
  std::vector<std::int32_t> nodes_;   // body vertices, grouped by seam position and piece
  std::vector<std::int32_t> starts_;  // group g is nodes_[starts_[g], starts_[g + 1])
  std::int32_t open_ = 0, file_vertices_ = 0, touching_ = 0;
};

}  // namespace conform::scenes
