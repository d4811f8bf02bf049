// SkinnedSoftBody's private side: the books mirroring the mesh into Bullet (per vertex, per
// face, per edge), the skin drive and the scratch of topology changes. The public class
// forwards to it (skinned_soft_body.hpp describes the behaviour). Parts that own their state
// (each header states its invariant): PieceHandles (piece_handles.hpp), KeptRest
// (kept_rest.hpp), DetachedVertices (detached_vertices.hpp), SkinDrive, MembraneDrive,
// TearGrowth. Its own members live by concept:
//   skinned_soft_body.cpp  facade: construction, edit entry points, queries, forwarders;
//   skin_drive.cpp         pose source, skinned targets, the per-substep update;
//   bullet_surgery.cpp     add/remove of nodes, faces and links, link constants, node areas;
//   piece_books.cpp        bodies per piece, moving a piece, detaching, bending links;
//   topology_mirror.cpp    a TopologyChange into Bullet, in phases over a MirrorContext;
//   piece_release.cpp      releasing a piece from skinning (a free Bullet soft body).
#pragma once

#include <BulletSoftBody/btSoftBody.h>

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <stdexcept>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "conform/bullet/convert.hpp"
#include "conform/bullet/skinned_soft_body.hpp"
#include "conform/mesh/adjacency.hpp"
#include "conform/mesh/analysis.hpp"
#include "conform/mesh/face_index.hpp"
#include "conform/mesh/split_search.hpp"
#include "detached_vertices.hpp"
#include "kept_rest.hpp"
#include "membrane_drive.hpp"
#include "piece_handles.hpp"
#include "skin_drive.hpp"
#include "tear_growth.hpp"

struct btDbvtNode;

namespace conform::bullet {

struct MirrorContext;

struct SkinnedSoftBody::Impl {
  // The public methods, documented in skinned_soft_body.hpp.
  Impl(const WorldLink& link, const mesh::SkinnedMesh& mesh, const skin::Skeleton& skeleton,
       const Material& material, const PieceSettings& settings);
  ~Impl();
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  // --- Pose sources (the last one set wins). Time is the plugin's simulated time, s. ---
  void set_pose(const skin::Pose& pose) {
    drive_.set_pose(pose);
    source_chosen_ = true;
  }
  void play(const skin::Animation& animation, skin::Blend blend = skin::Blend::linear,
            bool loop = true);
  void set_keyframes(skin::PoseTrack track, skin::Blend blend = skin::Blend::linear) {
    drive_.set_keyframes(std::move(track), blend);
    source_chosen_ = true;
  }
  void set_pose_source(std::function<void(double time, skin::Pose& pose)> source) {
    drive_.set_pose_source(std::move(source));
    source_chosen_ = true;
  }
  void set_skin_threads(int threads) { drive_.set_threads(threads); }
  void set_clock(const Clock& clock);
  void snap_to_pose();
  void place_on_pose();  // snap_to_pose() without the edit check (also from the first substep)
  void set_pinned(std::span<const std::int32_t> vertices);

  // --- Topology changes: on the simulated positions, only between stepSimulation calls. ---
  mesh::CutResult cut(const cga::Plane<double>& plane, const mesh::CutOptions& options = {});
  mesh::DrillResult drill(const mesh::DrillTool& tool, const mesh::DrillOptions& options = {});
  void begin_tear(const mesh::TearOptions& options = {});
  mesh::TearStep tear_advance(const mesh::ScalpelSample& sample);
  const mesh::Tear* tear() const { return tear_.get(); }
  void apply(const mesh::TopologyChange& change);
  const ApplyStats& last_apply() const { return stats_; }

  // --- State ---
  const mesh::SkinnedMesh& mesh() const { return mesh_; }
  const skin::Skeleton& skeleton() const { return skeleton_; }
  const Material& material() const { return material_; }
  /// The skin's rest state per vertex: the bind pose (the membrane's and growth's rest frame).
  Eigen::Ref<const Eigen::Matrix3Xd> skin_rest() const {
    if (bind_.cols() > 0) return bind_;
    return mesh_.rest;
  }
  void sync_mesh();
  std::int32_t vertex_count() const { return mesh_.vertex_count(); }
  std::int32_t piece_count() const;
  std::vector<btSoftBody*> pieces() const;
  inline Eigen::Vector3d position(std::int32_t vertex) const;  // below
  inline Eigen::Vector3d velocity(std::int32_t vertex) const;
  double mass(std::int32_t vertex) const { return mass_[static_cast<std::size_t>(vertex)]; }
  bool kinematic(std::int32_t vertex) const { return kinematic_[static_cast<std::size_t>(vertex)]; }
  inline btSoftBody* body_of(std::int32_t vertex) const;
  inline const btSoftBody::Node& node(std::int32_t vertex) const;
  std::int32_t vertex_of(const btSoftBody* body, int node) const;
  std::int32_t node_of(std::int32_t vertex) const {
    return node_of_[static_cast<std::size_t>(vertex)];
  }
  Eigen::Vector3d target(std::int32_t vertex) const { return drive_.target(vertex); }
  double total_mass() const;
  Eigen::Vector3d momentum() const;
  double momentum_scale() const;
  double rest_length(std::int32_t u, std::int32_t v) const;
  std::int32_t link_count() const;
  std::int32_t bending_link_count() const;
  double bending_rest_length(std::int32_t u, std::int32_t v) const;
  bool detached(std::int32_t vertex) const {
    return piece_of_[static_cast<std::size_t>(vertex)] < 0;
  }
  std::int32_t detached_count() const { return detached_.count(); }
  bool is_kinematic_by_weight(std::int32_t vertex) const;

  // --- Pieces (ids, events, per-piece settings: pieces_, piece_handles.hpp) ---
  using Piece = bullet::Piece;
  using PieceBody = bullet::PieceBody;
  PieceId piece_of(std::int32_t vertex) const;
  void set_piece_collision(PieceId id, int group, int mask);
  /// Throws std::logic_error when an edit named `what` may not run now: inside a step, or
  /// after the application deleted a piece's body.
  void check_editable(const char* what) const;
  // --- Render data (render_data.cpp) ---
  Eigen::Matrix3Xd normals() const;
  std::vector<skin::Versor> joint_transforms() const;
  void debug_draw(btIDebugDraw& drawer) const;
  // --- Release (piece_release.cpp) ---
  void release_piece(PieceId id, const ReleaseOptions& options);
  void release_nodes(Piece& piece);
  /// After an edit: released pieces' new nodes are free too, and a volume-keeping piece whose
  /// nodes changed keeps the volume it has now.
  void refresh_released();
  /// Each substep: the released, closed pieces' volume force, implicit (released_volume.cpp).
  void hold_released_volumes(double dt);

  // --- Skin drive (skin_drive.cpp): update() is the one per-substep entry point ---
  void update(double dt, double time);
  std::optional<NonFiniteNode> first_non_finite_node() const;        // non_finite_check.cpp
  Eigen::Vector3d own_velocity(const Piece& piece, int node) const;  // non_finite_check.cpp
  void skin_targets(double time);
  void drive_nodes(Piece& piece, double dt);
  // The membrane (Material::model == membrane) replaces drive_nodes and the rest lengths.
  bool membrane_model() const { return material_.model == MaterialModel::membrane; }
  void step_membrane(double dt);
  void reapply_rest_lengths(Piece& piece);

  // --- Piece books (piece_books.cpp) ---
  struct PieceMove;  // piece_books.cpp
  /// A new, empty piece in the world; its settings from `parent` (a slot; −1: the defaults).
  Piece& new_piece(std::int32_t parent = -1);
  void configure_body(btSoftBody& body, const Piece* parent);
  void build(const mesh::SkinnedMesh& mesh);
  void reserve_books(const mesh::SkinnedMesh& mesh);
  void index_faces(const mesh::SkinnedMesh& mesh);
  std::vector<std::int32_t> make_bodies(const mesh::Pieces& labels);
  void place_nodes(const mesh::SkinnedMesh& mesh, const mesh::Pieces& labels,
                   std::span<const std::int32_t> body_of_piece);
  void place_faces_and_links(const mesh::SkinnedMesh& mesh);
  void drop_empty_pieces();
  void detach(std::int32_t vertex);
  /// Moves a whole connected piece (its vertices in Bullet) into a new body, with room for
  /// `joining` nodes and `added_faces` faces still to come in this change; the body's index.
  std::int32_t move_to_new_piece(std::span<const std::int32_t> moving, std::int32_t joining,
                                 std::int32_t added_faces);
  void gather_move(PieceMove& move);
  void mark_moving_links(PieceMove& move);
  void open_new_body(PieceMove& move, std::int32_t joining, std::int32_t added_faces);
  void copy_moving_nodes(PieceMove& move);
  void move_faces(PieceMove& move);
  void move_links(PieceMove& move);
  std::vector<btDbvtNode*> leave_old_bodies(PieceMove& move);
  void refresh_bending(std::int32_t a, std::int32_t b);

  // --- Bullet surgery (bullet_surgery.cpp) ---
  void set_node_mass(std::int32_t vertex);
  /// `near`: a vertex next to it whose tree leaf it joins (−1: Bullet's own insert).
  void add_node(std::int32_t piece, std::int32_t vertex, const Eigen::Vector3d& x,
                const Eigen::Vector3d& v, std::int32_t near = -1);
  void remove_node(std::int32_t vertex);
  void remove_nodes_highest_first(std::span<const std::int32_t> vertices);
  void add_face(std::int32_t piece, std::int32_t face);
  void remove_face_from_bullet(std::int32_t face);
  void remove_face_slot(std::int32_t face);  // out of its body only (no links, no stats)
  void add_link(std::int32_t piece, std::int32_t u, std::int32_t v, double rest);
  void remove_link(std::int32_t piece, std::int32_t link);
  void pop_link(std::int32_t piece, std::int32_t link);  // out of Bullet, key kept
  void add_bending(std::int32_t piece, std::int32_t a, std::int32_t b, std::int32_t c,
                   std::int32_t d, double rest);
  void remove_bending(std::int32_t a, std::int32_t b);
  void update_link_constants(std::int32_t vertex);
  void update_node_area(std::int32_t vertex);

  // --- Topology mirror (topology_mirror.cpp): its phases, in order ---
  void mirror(const mesh::TopologyChange& change);
  void make_new_vertices(MirrorContext& c);
  void remove_faces(MirrorContext& c);
  void assign_face_slots(MirrorContext& c);
  void move_face_slot(std::int32_t last, std::int32_t slot);  // step 3's swap-with-last
  void find_pieces(MirrorContext& c);
  void move_pieces(MirrorContext& c);
  void move_into_body(MirrorContext& c, std::span<const std::int32_t> moving, std::int32_t into);
  void place_changed_nodes(MirrorContext& c);
  void insert_faces_and_links(MirrorContext& c);
  void refresh_changed_bending();
  void refresh_changed_areas(MirrorContext& c);

  btSoftBodyWorldInfo* info_;
  WorldLink link_;
  PieceSettings defaults_;  // of the pieces made at construction
  mesh::SkinnedMesh mesh_;
  mesh::Adjacency adjacency_;
  // Tear starts and drills query it; synced positions only mark it moved, so its refit is paid
  // when a tear starts or a drill runs, not every step (face_index.hpp).
  mesh::FaceIndex face_index_;
  skin::Skeleton skeleton_;
  Material material_;
  std::unique_ptr<mesh::Tear> tear_;
  TearGrowth growth_{[this] { return skin_rest(); }};  // the tear's own growth
  SkinDrive drive_;                                    // after skeleton_, which it reads
  MembraneDrive membrane_;
  // The bind pose where the mesh's rest points are not it (SkinDrive::bind_pose), else empty.
  Eigen::Matrix3Xd bind_;
  std::vector<std::string> warnings_;  // material_fit.hpp, at construction
  std::vector<void*> vertex_node_;     // per vertex: its btSoftBody::Node (null when detached)
  Eigen::Matrix3Xd target_matrix_, previous_matrix_;
  std::vector<btVector3> volume_gradient_;  // hold_released_volumes' ∂V/∂x_i, reused

  // Per vertex.
  std::vector<std::int32_t> piece_of_, node_of_;
  std::vector<double> mass_;
  std::vector<std::uint8_t> kinematic_, pinned_;
  std::vector<std::vector<std::int32_t>> vertex_faces_;  // incident mesh faces
  // Per mesh face: the faces as of the change being mirrored, and where each lives in Bullet.
  // faces_ is a second copy of mesh_.faces on purpose, equal to it between edits. mesh::drill
  // and Tear::advance apply several changes to mesh_ in one call (each computed on the mesh the
  // previous one left), and the mirror replays them one by one afterwards. While change i is
  // mirrored, mesh_ already holds the faces after the last change. The mirror also needs the
  // vertices of each removed face, which mesh::apply has overwritten or popped by then.
  // faces_ follows every change by the same slot rule (mesh::visit_face_slots), so a face
  // index means the same face in both once the last change is mirrored
  // (tests: expect_mirrors_mesh). Bullet's own face order is per body (face_piece_,
  // face_slot_; Piece::face_id maps back), not this array.
  std::vector<mesh::Face> faces_;
  std::vector<std::int32_t> face_piece_, face_slot_;
  // Per undirected edge (min, max): faces using it, and its link index in its piece.
  mesh::EdgeMap edge_faces_, edge_link_;
  // Per undirected edge (min, max) crossed by a bending link: its link index in its piece.
  mesh::EdgeMap bend_link_;
  // Detached vertices: their position and velocity when they left Bullet.
  DetachedVertices detached_;
  // The split search of a change (its per-vertex labels stay allocated between changes).
  mesh::SplitSearch split_;
  std::vector<std::int32_t> move_slot_;  // per vertex: its node in a new body (−1 between)
  KeptRest kept_;  // rest lengths of the links a change removed that may come back
  std::vector<std::uint8_t> area_mark_, seed_mark_;  // per vertex scratch, 0 between changes
  // Edges whose bending link may have to be made again at the end of a change.
  std::vector<std::pair<std::int32_t, std::int32_t>> bend_dirty_;

  PieceHandles pieces_;
  double time_ = 0;                           // of the last substep (targets after an edit)
  double last_dt_ = 0;                        // the last substep's length
  std::uint64_t topology_version_ = 0;        // changes mirrored
  std::optional<mesh::ScalpelSample> blade_;  // the last tear sample (debug drawing)
  std::optional<Clock> clock_;                // the body's own animation clock, when set
  double clock_now_ = 0;                      // the time the pose source was last sampled at
  bool started_ = false;        // stepped or snapped once: the first substep's start is done
  bool source_chosen_ = false;  // a pose source was set: the first substep starts on its pose
  ApplyStats stats_;
};

// --- The inline queries of the books ---

inline btSoftBody* SkinnedSoftBody::Impl::body_of(std::int32_t v) const {
  const std::int32_t p = piece_of_[static_cast<std::size_t>(v)];
  return p < 0 ? nullptr : pieces_[static_cast<std::size_t>(p)]->body.get();
}

// The node of an attached vertex (its body deleted by the application: refused).
inline const btSoftBody::Node& SkinnedSoftBody::Impl::node(std::int32_t v) const {
  const btSoftBody* body = body_of(v);
  if (!body) throw std::logic_error("SkinnedSoftBody: " + pieces_.lost());
  return body->m_nodes[node_of_[static_cast<std::size_t>(v)]];
}

inline Eigen::Vector3d SkinnedSoftBody::Impl::position(std::int32_t v) const {
  const auto i = static_cast<std::size_t>(v);
  if (piece_of_[i] < 0) return detached_.position(v);
  return from_bt(node(v).m_x);
}

inline Eigen::Vector3d SkinnedSoftBody::Impl::velocity(std::int32_t v) const {
  const auto i = static_cast<std::size_t>(v);
  if (piece_of_[i] < 0) return detached_.velocity(v);
  return from_bt(node(v).m_v);
}

}  // namespace conform::bullet
