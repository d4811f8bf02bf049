// A Bullet soft body skinned by CGA motor skinning (eq 17) whose topology changes at run time
// (cut, tear, drill) while it simulates: nodes = vertices, links = face edges, faces =
// triangles, one btSoftBody per connected piece. Promises: edits conserve mass and momentum
// exactly (a vertex left without faces leaves Bullet but stays in the books); vertex indices
// never change (face indices do, see topology_version()); an edit costs time proportional to
// the change and never resets the whole body. Each substep skins one target per vertex and
// drives the nodes toward theirs, by the skin membrane (default) or by Bullet's links. The
// mapping, the promises in full, how edits and substeps work, and why: docs/notes/plugin.md,
// "The skinned soft body's design (skinned_soft_body.hpp)".
#pragma once

#include "conform/bullet/precision.hpp"  // the package's Bullet precision, checked

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <functional>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "conform/bullet/non_finite_state.hpp"
#include "conform/bullet/piece.hpp"
#include "conform/bullet/tear_growth.hpp"
#include "conform/cga/plane.hpp"
#include "conform/membrane/skin_material.hpp"
#include "conform/membrane/solver_settings.hpp"
#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "conform/mesh/skinned_mesh.hpp"
#include "conform/mesh/tear.hpp"
#include "conform/mesh/topology_change.hpp"
#include "conform/skin/animation.hpp"
#include "conform/skin/pose.hpp"
#include "conform/skin/skeleton.hpp"

class btSoftBody;
class btIDebugDraw;
struct btSoftBodyWorldInfo;

namespace conform::bullet {

/// How a skinned soft body's skin resists deformation.
enum class MaterialModel {
  /// The skin membrane (core/membrane): pre-stressed triangles (SkinMaterial::law) in SI units
  /// attached to the skinned targets by the subcutaneous layer, solved each substep to a
  /// residual (Material::skin, Material::solver). Mesh- and solver-independent; the default.
  membrane,
  /// Bullet's own mass-spring links (position-based, kLST per iteration): the fields from
  /// link_stiffness to bending_stiffness below. Its stiffness depends on the iterations, the
  /// substeps and the mesh; kept for comparison and for cloth-like uses.
  bullet_links,
};

/// Physical parameters of a skinned soft body. Units are SI (metres, kilograms, seconds).
struct Material {
  MaterialModel model = MaterialModel::membrane;
  /// bullet_links: Bullet's linear stiffness kLST, dimensionless in (0, 1]: the fraction of a
  /// link's length error its position solver removes per iteration.
  double link_stiffness = 0.9;
  /// bullet_links: Bullet's damping kDP, dimensionless in [0, 1): fraction of velocity removed
  /// per substep. The membrane ignores it (its bodies run with kDP = 0): its damping is
  /// skin.attachment_damping, in Pa s/m.
  double damping = 0.0;
  /// Pretension s, dimensionless in [0, 1): a link's rest length is (1 − s) × its length when
  /// the link is made (at creation, or when a topology change adds it).
  double pretension = 0.0;
  /// bullet_links: areal mass density, kg/m². Each node gets a third of the area of its faces
  /// times this (skin about 1 mm thick ≈ 1.1 kg/m²). The membrane uses skin.areal_density.
  double density = 1.1;
  /// bullet_links: pull of a free node toward its skinned target per metre of offset, 1/s² (the
  /// squared angular frequency of the node's own spring). 0 leaves free nodes to the links alone.
  double target_stiffness = 400.0;
  /// bullet_links: damping of a free node's velocity relative to its target's velocity, 1/s.
  double target_damping = 20.0;
  /// bullet_links: nodes whose largest bone weight is ≥ this are kinematic; > 1 makes none
  /// kinematic by weight (pinned vertices still are). With the membrane only pinned vertices
  /// are kinematic: the attachment makes every other node follow its target.
  double kinematic_weight = 0.999;
  /// Bullet's position iterations per substep (its link solve and its contacts).
  int position_iterations = 4;
  /// Bending links: Bullet's linear stiffness kLST of a link joining the two vertices opposite
  /// each edge shared by exactly two faces, dimensionless in [0, 1]. 0 (default) makes none.
  /// Rest lengths follow the pretension rule of the edge links. They are kept through
  /// topology changes: a link across an edge that is cut, torn or removed goes with it.
  double bending_stiffness = 0.0;
  /// Collision margin of the pieces, m.
  double margin = 0.005;
  /// A node faster than this past its skinned target (its velocity less the target's; a
  /// released piece's whole velocity), in the world's length unit per second, is a runaway: the
  /// plugin stops the step with bullet::NonFiniteState naming it, as it does for a NaN (an unstable
  /// integration often grows for many steps before it overflows, writing finite garbage). > 0.
  /// The default, infinity, turns the check off, since the plugin does not know the world's
  /// unit; the scenes (in metres) set 100 m/s, far above any motion of a body's skin.
  double max_speed = std::numeric_limits<double>::infinity();
  /// membrane: the skin's material (SI units, sourced defaults for human skin).
  membrane::SkinMaterial skin{};
  /// membrane: the solve of each substep (tolerance in Pa of nodal traction).
  membrane::SolverSettings solver{};
  /// membrane: the tear's own growth by Griffith's criterion (tear_growth.hpp), off by
  /// default; SkinnedSoftBody::grow_tear() runs it.
  TearGrowthSettings growth{};
};

/// A number field of Material, by its name.
struct MaterialField {
  const char* name;
  double Material::*value;
};

/// The fields only the bullet_links model reads, which the membrane ignores: the body names the
/// ones set away from their defaults in its material_warnings.
inline constexpr std::array<MaterialField, 6> kLinkOnlyFields{{
    {"link_stiffness", &Material::link_stiffness},
    {"damping", &Material::damping},
    {"pretension", &Material::pretension},
    {"target_stiffness", &Material::target_stiffness},
    {"target_damping", &Material::target_damping},
    {"kinematic_weight", &Material::kinematic_weight},
}};

/// How a skinned body reaches its world (Plugin::add_skinned_body makes one).
struct WorldLink {
  btSoftBodyWorldInfo* info = nullptr;
  /// Adds a piece's body to the world with its broadphase group and mask.
  std::function<void(btSoftBody*, int group, int mask)> add{};
  std::function<void(btSoftBody*)> remove{};
  /// True while the world steps: edits are then refused (empty: never).
  std::function<bool()> stepping{};
};

/// What one applied TopologyChange did to the Bullet side.
struct ApplyStats {
  std::int32_t new_nodes = 0;
  std::int32_t removed_faces = 0, added_faces = 0;
  std::int32_t removed_links = 0, added_links = 0;
  std::int32_t moved_nodes = 0;  // nodes moved into another piece (a split)
  std::int32_t new_pieces = 0;
  std::int32_t detached_nodes = 0;  // vertices left without faces, taken out of Bullet
  std::int32_t removed_bending = 0, added_bending = 0;
  std::int32_t searched_vertices = 0;  // visited by the split search
  /// Where the time of the last cut / drill / tear step / apply went, s (CPU time of the
  /// calling thread): the sync of the simulated positions into the mesh, the mesh side
  /// (computing the change and applying it to the mesh, in core), and the plugin's own mirror
  /// of it into Bullet, by phase.
  struct Seconds {
    double sync = 0;      // simulated positions → mesh().current
    double mesh = 0;      // computing the change and applying it to the mesh (core)
    double vertices = 0;  // new vertices: positions, velocities, masses
    double faces = 0;     // removed faces and links out of Bullet, face slots
    double pieces = 0;    // which connected piece each affected vertex belongs to
    double split = 0;     // nodes moved into other (possibly new) bodies
    double insert = 0;    // new nodes, faces and links into Bullet
    double mirror() const { return vertices + faces + pieces + split + insert; }
    double total() const { return sync + mesh + mirror(); }
  } seconds;
};

class SkinnedSoftBody {
 public:
  /// Builds the pieces of `mesh` (its `current` positions are the initial node positions) and
  /// adds them to the world through `link.add`, each with `settings`. `skeleton` is copied.
  /// Throws std::invalid_argument on inconsistent input. Normally made by
  /// Plugin::add_skinned_body.
  SkinnedSoftBody(const WorldLink& link, const mesh::SkinnedMesh& mesh,
                  const skin::Skeleton& skeleton, const Material& material,
                  const PieceSettings& settings = {});
  ~SkinnedSoftBody();
  SkinnedSoftBody(const SkinnedSoftBody&) = delete;
  SkinnedSoftBody& operator=(const SkinnedSoftBody&) = delete;

  // --- Pose sources (the last one set wins). Time is the plugin's simulated time, s. ---
  /// A fixed pose.
  void set_pose(const skin::Pose& pose);
  /// An animation sampled at the simulated time (wrapped when `loop`). The animation is copied.
  /// Throws std::invalid_argument when it does not fit the skeleton (Animation::validate).
  void play(const skin::Animation& animation, skin::Blend blend = skin::Blend::linear,
            bool loop = true);
  /// Keyframes set by the user, sampled at the simulated time.
  void set_keyframes(skin::PoseTrack track, skin::Blend blend = skin::Blend::linear);
  /// Any other source, e.g. an arm rig: writes the pose for `time` into `pose`.
  void set_pose_source(std::function<void(double time, skin::Pose& pose)> source);
  /// Where the body is in the world: the skinned targets (model space, as the mesh and the
  /// skeleton) are placed by this rigid transform (default identity) from the next substep
  /// on; the nodes follow through the drive, or at once with snap_to_pose(). Positions,
  /// targets, cut planes, tear samples and drill tools are in world space; mesh().rest stays
  /// in model space.
  void set_world_transform(const Eigen::Isometry3d& transform);
  const Eigen::Isometry3d& world_transform() const;
  /// The body's own animation clock (opt-in): from this call on, the pose source is sampled at
  /// start + speed × (simulated time since the call), frozen while paused (call again to
  /// change speed or to pause; `start` then restarts it). Without it: the plugin's time.
  struct Clock {
    double start = 0;  // s
    double speed = 1;  // finite; negative runs backwards
    bool paused = false;
  };
  void set_clock(const Clock& clock);
  /// The time the pose source was last sampled at, s.
  double clock_time() const;
  /// Places every node in Bullet on its skinned target at the current time, at rest (position
  /// = target, velocity 0). The body's first substep does this by itself when a pose source
  /// was set (set_pose, play, set_keyframes or set_pose_source), at the substep's start time,
  /// so that it does not jump from the bind pose it was built in to the source's first pose;
  /// without a pose source the nodes start where the mesh's `current` put them. Call it to
  /// place the body again later (after a jump of the pose source or of the world transform).
  void snap_to_pose();
  /// OpenMP threads of the skinning loop; 0 = the library's choice. Default 1: a fork/join
  /// every substep costs more than it saves on a few thousand vertices, and idle OpenMP
  /// workers slow Bullet's step (docs/notes/plugin.md).
  void set_skin_threads(int threads);
  /// Makes these vertices kinematic regardless of their weights (and the rest free unless
  /// above the weight threshold).
  void set_pinned(std::span<const std::int32_t> vertices);

  // --- Topology changes: on the simulated positions, only between stepSimulation calls (an
  // edit from the plugin's action, i.e. a step hook or a pose source, throws
  // std::logic_error; one from the application's own internal tick callback is not detected).
  // Every query below is valid right after an edit, new vertices included. ---
  mesh::CutResult cut(const cga::Plane<double>& plane, const mesh::CutOptions& options = {});
  mesh::DrillResult drill(const mesh::DrillTool& tool, const mesh::DrillOptions& options = {});
  /// Starts a tear (replacing any earlier one); advance it with tear_advance().
  void begin_tear(const mesh::TearOptions& options = {});
  mesh::TearStep tear_advance(const mesh::ScalpelSample& sample);
  const mesh::Tear* tear() const;
  /// Grows the tear at its tips where the energy release rate reaches the skin's toughness
  /// (tear_growth.hpp): nothing unless Material::growth is enabled, the model is the membrane
  /// and a tear has begun. Call it between steps, e.g. after each stepSimulation. The tear takes
  /// each grown segment (tear() then includes it), so a blade and growth can act on one tear in
  /// any order: the blade cuts on from a grown tip, and growth judges the blade's tip.
  TearGrowthReport grow_tear();
  /// Rest-space length the tear has grown by itself since it began, m.
  double tear_grown_length() const;
  /// Applies a change computed by the caller on mesh() (after sync_mesh()).
  void apply(const mesh::TopologyChange& change);
  const ApplyStats& last_apply() const;

  // --- Pieces: handles, events, inherited settings, release (piece.hpp) ---
  /// The live pieces' ids (bodies holding nodes), in slot order.
  std::vector<PieceId> piece_ids() const;
  /// Whether `id` names a live piece of this body (false for a stale or null id).
  bool piece_valid(PieceId id) const;
  /// The live piece's btSoftBody, or null for a stale or null id.
  btSoftBody* piece_body(PieceId id) const;
  /// The piece holding `vertex` (null for a detached vertex).
  PieceId piece_of(std::int32_t vertex) const;
  /// Adds a listener of piece events (created, removed, body destroyed).
  void on_piece_event(std::function<void(const PieceEvent&)> listener);
  /// The piece's settings (throws std::invalid_argument for a stale id; so do the setters).
  const PieceSettings& piece_settings(PieceId id) const;
  void set_piece_user(PieceId id, void* user);
  /// Re-adds the piece's body to the world with this broadphase group and mask.
  void set_piece_collision(PieceId id, int group, int mask);
  /// Releases the piece from skinning (ReleaseOptions); pieces split from it stay released.
  void release_piece(PieceId id, const ReleaseOptions& options = {});
  bool piece_released(PieceId id) const;

  // --- State ---
  /// The mesh with `current` = the simulated node positions as of the last sync_mesh().
  const mesh::SkinnedMesh& mesh() const;
  const skin::Skeleton& skeleton() const;
  const Material& material() const;
  /// What does not fit between the material and the mesh, found when the body was made, each
  /// naming the field and the figure: bullet_links fields set away from their defaults while the
  /// model is the membrane (ignored), and an attachment whose decay length sqrt(E'' t / k) is
  /// below half the median edge (the skin's tension then acts element by element).
  const std::vector<std::string>& material_warnings() const;
  void sync_mesh();
  std::int32_t vertex_count() const;
  /// Connected pieces of the mesh (bodies holding faces).
  std::int32_t piece_count() const;
  /// Every soft body in the world, including one whose faces were all removed and that only
  /// keeps its loose nodes (and their mass).
  std::vector<btSoftBody*> pieces() const;
  Eigen::Vector3d position(std::int32_t vertex) const;
  Eigen::Vector3d velocity(std::int32_t vertex) const;
  /// Own mass bookkeeping, kg (kinematic nodes have a mass here but inverse mass 0 in Bullet).
  double mass(std::int32_t vertex) const;
  bool kinematic(std::int32_t vertex) const;
  /// The Bullet soft body holding `vertex` and its node index there.
  btSoftBody* body_of(std::int32_t vertex) const;
  /// The vertex of node `node` of `body` (one of pieces()), or −1.
  std::int32_t vertex_of(const btSoftBody* body, int node) const;
  std::int32_t node_of(std::int32_t vertex) const;
  /// Skinned target of `vertex` from the last substep (or from creation).
  Eigen::Vector3d target(std::int32_t vertex) const;
  double total_mass() const;
  Eigen::Vector3d momentum() const;
  /// Σ m |v|, the scale against which momentum errors are relative.
  double momentum_scale() const;
  /// Our rest length of the link between two vertices (−1 when there is none).
  double rest_length(std::int32_t u, std::int32_t v) const;
  /// Edge links (one per mesh edge) over all pieces.
  std::int32_t link_count() const;
  /// Bending links over all pieces, and our rest length of the one across edge (u, v) (−1).
  std::int32_t bending_link_count() const;
  double bending_rest_length(std::int32_t u, std::int32_t v) const;
  /// The vertex left Bullet (it has no faces; e.g. the inside of a drilled hole): no node,
  /// link, face or collision of its own. Its mass stays in the books. position() and
  /// velocity() are its state when it left (so an edit conserves Σm and Σm·v exactly) until
  /// the next substep, and from then on its skinned target's (it rides the skeleton like
  /// removed material held by the tool, and never drifts from its target); body_of() is null
  /// and node_of() −1.
  bool detached(std::int32_t vertex) const;
  std::int32_t detached_count() const;

  // --- Render data and pose (render_data.cpp) ---
  /// Changes mirrored since construction: +1 per TopologyChange (a drill or tear step may
  /// apply several). Face and vertex indices of mesh() may be reshuffled whenever it changes.
  std::uint64_t topology_version() const;
  /// Per face of mesh(): skin, cap or tube wall, and the change that made it (op n: the n-th
  /// TopologyChange applied to the mesh, as mesh().edits counts them; equal to
  /// topology_version() at that change for a mesh given without edits; 0: the model's face).
  /// Tags follow their faces through every edit and split into pieces (skinned_mesh.hpp).
  std::span<const mesh::FaceTag> face_tags() const;
  /// Per vertex, the unit area-weighted normal of its faces at the simulated positions (zero
  /// for a vertex without faces); #V by 3 columns as mesh().current.
  Eigen::Matrix3Xd normals() const;
  /// The skeleton pose of the last substep (local versors; the rest pose before the first).
  const skin::Pose& pose() const;
  /// The global versor of every joint for pose() (joint space → mesh space).
  std::vector<skin::Versor> joint_transforms() const;
  /// Draws the skeleton (joint to parent, yellow), for every driven node in Bullet the offset
  /// to its skinned target (cyan), the tear's two borders (orange, one line per border edge)
  /// and the blade of the last tear sample (magenta). Called by the plugin's action from
  /// btDynamicsWorld::debugDrawWorld; Bullet draws the pieces themselves.
  void debug_draw(btIDebugDraw& drawer) const;

  /// The membrane's solve of the last substep (residual in Pa, iterations); zero with
  /// bullet_links.
  const membrane::SolveReport& last_solve() const;

  /// One substep, called by the plugin's action: pose, skin, drive nodes, re-apply rest lengths.
  void update(double dt, double time);
  /// The first node (pieces in slot order, nodes in body order) whose position or velocity is
  /// NaN or infinite, or none. One pass over the nodes; the plugin's action calls it before
  /// every substep's update() and throws NonFiniteState (non_finite_state.hpp) on a hit.
  std::optional<NonFiniteNode> first_non_finite_node() const;
  /// Skinning only, for `time` (targets() are then valid); used by update() and benchmarks.
  void skin_targets(double time);

 private:
  struct Impl;  // skinned_soft_body_impl.hpp
  std::unique_ptr<Impl> impl_;
};

}  // namespace conform::bullet
