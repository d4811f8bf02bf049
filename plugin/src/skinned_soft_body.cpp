// SkinnedSoftBody's facade: construction, the topology edits' entry points (the mesh side in
// core, then the mirror into Bullet), the read-only queries, and the public class's forwarders.
#include "conform/bullet/skinned_soft_body.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

#include "conform/skin/limb_axes.hpp"
#include "edge_key.hpp"
#include "material_fit.hpp"
#include "phase_clock.hpp"
#include "skinned_soft_body_impl.hpp"

namespace conform::bullet {

namespace {

// Bad input throws naming it (ARCHITECTURE.md, Errors): the field, its value, the range.
void require(bool ok, const char* field, double value, const char* range) {
  if (ok) return;
  std::ostringstream out;
  out << "SkinnedSoftBody: material " << field << " = " << value << " is out of range (" << range
      << ")";
  throw std::invalid_argument(out.str());
}

void validate(const mesh::SkinnedMesh& mesh, const skin::Skeleton& skeleton) {
  const std::int32_t n = mesh.vertex_count();
  if (n == 0) throw std::invalid_argument("SkinnedSoftBody: empty mesh");
  if (mesh.current.cols() != n || mesh.bones.cols() != n || mesh.weights.cols() != n)
    throw std::invalid_argument("SkinnedSoftBody: " + std::to_string(n) + " rest points but " +
                                std::to_string(mesh.current.cols()) + " current, " +
                                std::to_string(mesh.bones.cols()) + " bone and " +
                                std::to_string(mesh.weights.cols()) +
                                " weight columns (need one per vertex)");
  if (skeleton.bone_count() == 0) throw std::invalid_argument("SkinnedSoftBody: no bones");
  if (!mesh.face_tags.empty() && !mesh.has_face_tags())
    throw std::invalid_argument("SkinnedSoftBody: " + std::to_string(mesh.face_tags.size()) +
                                " face tags for " + std::to_string(mesh.faces.size()) +
                                " faces (need one per face, or none)");
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (const auto v : mesh.faces[f])
      if (v < 0 || v >= n)
        throw std::invalid_argument("SkinnedSoftBody: face " + std::to_string(f) + " has vertex " +
                                    std::to_string(v) + ", out of range [0, " + std::to_string(n) +
                                    ")");
  // Refused, not dropped: dropping would renumber the faces after it, so the caller's face
  // ids would no longer name the body's faces (the importer is where such faces are dropped).
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& t = mesh.faces[f];
    if (t[0] == t[1] || t[1] == t[2] || t[2] == t[0])
      throw std::invalid_argument("SkinnedSoftBody: face " + std::to_string(f) +
                                  " repeats vertex " + std::to_string(t[1] == t[2] ? t[1] : t[0]) +
                                  " (a triangle needs 3 distinct vertices)");
  }
  for (std::int32_t v = 0; v < n; ++v)
    for (int k = 0; k < mesh::kMaxInfluences; ++k)
      if (mesh.weights(k, v) != 0 &&
          (mesh.bones(k, v) < 0 || mesh.bones(k, v) >= skeleton.bone_count()))
        throw std::invalid_argument("SkinnedSoftBody: vertex " + std::to_string(v) +
                                    " has bone id " + std::to_string(mesh.bones(k, v)) +
                                    ", out of range [0, " + std::to_string(skeleton.bone_count()) +
                                    ")");
}

void validate(const Material& material) {
  const auto finite = [](double v) { return std::isfinite(v); };
  const auto model = static_cast<int>(material.model);
  require(model == static_cast<int>(MaterialModel::membrane) ||
              model == static_cast<int>(MaterialModel::bullet_links),
          "model", model, "membrane (0) or bullet_links (1)");
  require(finite(material.link_stiffness) && material.link_stiffness > 0 &&
              material.link_stiffness <= 1,
          "link_stiffness", material.link_stiffness, "(0, 1]");
  require(finite(material.damping) && material.damping >= 0 && material.damping < 1, "damping",
          material.damping, "[0, 1)");
  require(finite(material.pretension) && material.pretension >= 0 && material.pretension < 1,
          "pretension", material.pretension, "[0, 1)");
  require(finite(material.density) && material.density > 0, "density", material.density,
          "> 0 kg/m^2");
  require(finite(material.target_stiffness) && material.target_stiffness >= 0, "target_stiffness",
          material.target_stiffness, ">= 0 1/s^2");
  require(finite(material.target_damping) && material.target_damping >= 0, "target_damping",
          material.target_damping, ">= 0 1/s");
  require(finite(material.kinematic_weight) && material.kinematic_weight > 0, "kinematic_weight",
          material.kinematic_weight, "> 0 (> 1: none by weight)");
  require(material.position_iterations >= 1 && material.position_iterations <= 1000,
          "position_iterations", material.position_iterations, "[1, 1000]");
  require(finite(material.bending_stiffness) && material.bending_stiffness >= 0 &&
              material.bending_stiffness <= 1,
          "bending_stiffness", material.bending_stiffness, "[0, 1]");
  require(finite(material.margin) && material.margin >= 0 && material.margin <= 1, "margin",
          material.margin, "[0, 1] m");
  require(!std::isnan(material.max_speed) && material.max_speed > 0, "max_speed",
          material.max_speed, "> 0 m/s (infinity: no bound)");
  if (material.model == MaterialModel::membrane) {
    material.skin.validate();  // throws naming the field and its value
    material.solver.validate();
    material.growth.validate();
  }
}

// Masses: a third of each face's area to each of its vertices; vertices without faces still
// carry some mass (the mean of the others).
std::vector<double> vertex_masses(const mesh::SkinnedMesh& mesh, double density) {
  std::vector<double> mass(static_cast<std::size_t>(mesh.vertex_count()), 0.0);
  for (const auto& f : mesh.faces) {
    const Eigen::Vector3d a = mesh.current.col(f[0]), b = mesh.current.col(f[1]),
                          c = mesh.current.col(f[2]);
    const double m = density * 0.5 * (b - a).cross(c - a).norm() / 3;
    for (const auto v : f) mass[static_cast<std::size_t>(v)] += m;
  }
  double sum = 0;
  int count = 0;
  for (const double m : mass)
    if (m > 0) sum += m, ++count;
  const double fallback = count ? sum / count : density * 1e-6;
  for (double& m : mass)
    if (!(m > 0)) m = fallback;
  return mass;
}

}  // namespace

SkinnedSoftBody::Impl::Impl(const WorldLink& link, const mesh::SkinnedMesh& mesh,
                            const skin::Skeleton& skeleton, const Material& material,
                            const PieceSettings& settings)
    : info_(link.info),
      link_(link),
      defaults_(settings),
      mesh_(mesh),
      skeleton_(skeleton),
      material_(material),
      drive_(skeleton_) {
  if (!info_ || !link_.add || !link_.remove)
    throw std::invalid_argument(
        "SkinnedSoftBody: the world link lacks its world info, add or remove");
  validate(mesh_, skeleton_);
  validate(material_);
  membrane_.set_bone_axes(skin::bone_axes(skeleton_));
  mesh_.face_tags.resize(mesh_.faces.size());  // a mesh without tags: all skin, from the model
  if (membrane_model()) material_.density = material_.skin.areal_density;  // the books' masses
  adjacency_.build(mesh_);
  face_index_.build(mesh_);
  mass_ = vertex_masses(mesh_, material_.density);
  const std::int32_t n = mesh_.vertex_count();
  pinned_.assign(static_cast<std::size_t>(n), 0);
  kinematic_.resize(static_cast<std::size_t>(n));
  for (std::int32_t v = 0; v < n; ++v)
    kinematic_[static_cast<std::size_t>(v)] = is_kinematic_by_weight(v);
  drive_.start(mesh_);
  bind_ = drive_.bind_pose(mesh_);
  warnings_ = material_fit_warnings(material, skin_rest(), mesh_.faces);
  build(mesh_);
}

SkinnedSoftBody::Impl::~Impl() {
  // A body in a world has a broadphase handle; one whose world was destroyed first has none
  // (Bullet's world destructor clears them) and is deleted without touching the world. Bodies
  // the application deleted are gone from the books already (PieceBody).
  for (auto& piece : pieces_)
    if (piece && piece->body && piece->body->getBroadphaseHandle()) link_.remove(piece->body.get());
  pieces_.destroyed();
}

void SkinnedSoftBody::Impl::play(const skin::Animation& animation, skin::Blend blend, bool loop) {
  // Sampling trusts the channels' joint ids: a foreign animation would write past the pose.
  const std::string problem = animation.validate(skeleton_);
  if (!problem.empty())
    throw std::invalid_argument("SkinnedSoftBody::play: animation '" + animation.name +
                                "' does not fit the skeleton: " + problem);
  drive_.play(animation, blend, loop);
  source_chosen_ = true;
}

bool SkinnedSoftBody::Impl::is_kinematic_by_weight(std::int32_t v) const {
  return !membrane_model() && mesh_.weights(0, v) >= material_.kinematic_weight;
}

void SkinnedSoftBody::Impl::apply(const mesh::TopologyChange& change) {
  check_editable("apply");
  stats_ = {};
  double clock = thread_seconds();
  mesh::apply(mesh_, change, &adjacency_);
  face_index_.update(mesh_, change);
  stats_.seconds.mesh += seconds_since(clock);
  mirror(change);
  drive_.extend(mesh_);
}

void SkinnedSoftBody::Impl::sync_mesh() {
  for (std::int32_t v = 0; v < mesh_.vertex_count(); ++v) mesh_.current.col(v) = position(v);
  face_index_.mark_moved();
}

mesh::CutResult SkinnedSoftBody::Impl::cut(const cga::Plane<double>& plane,
                                           const mesh::CutOptions& options) {
  check_editable("cut");
  stats_ = {};
  double clock = thread_seconds();
  sync_mesh();
  const double sync = seconds_since(clock);
  mesh::CutResult result = mesh::compute_cut(mesh_, plane, options);
  const double compute = seconds_since(clock);
  if (result.status == mesh::CutStatus::Cut) apply(result.change);
  stats_.seconds.sync = sync;
  stats_.seconds.mesh += compute;
  return result;
}

mesh::DrillResult SkinnedSoftBody::Impl::drill(const mesh::DrillTool& tool,
                                               const mesh::DrillOptions& options) {
  check_editable("drill");
  stats_ = {};
  double clock = thread_seconds();
  sync_mesh();
  stats_.seconds.sync = seconds_since(clock);
  mesh::DrillResult result = mesh::drill(mesh_, adjacency_, face_index_, tool, options);
  stats_.seconds.mesh = seconds_since(clock);
  for (const auto& change : result.changes) mirror(change);
  drive_.extend(mesh_);
  return result;
}

void SkinnedSoftBody::Impl::begin_tear(const mesh::TearOptions& options) {
  check_editable("begin_tear");
  tear_ = std::make_unique<mesh::Tear>(mesh_, adjacency_, face_index_, options);
  growth_.reset();
  blade_.reset();
}

mesh::TearStep SkinnedSoftBody::Impl::tear_advance(const mesh::ScalpelSample& sample) {
  check_editable("tear_advance");
  if (!tear_) begin_tear();
  stats_ = {};
  double clock = thread_seconds();
  sync_mesh();
  stats_.seconds.sync = seconds_since(clock);
  mesh::TearStep step = tear_->advance(sample);
  blade_ = sample;  // drawn by debug_draw
  stats_.seconds.mesh = seconds_since(clock);
  for (const auto& change : step.changes) mirror(change);
  drive_.extend(mesh_);
  return step;
}

// --- Queries ---

std::int32_t SkinnedSoftBody::Impl::piece_count() const {
  return std::int32_t(std::count_if(pieces_.begin(), pieces_.end(), [](auto& p) {
    return p && p->body && p->body->m_faces.size() > 0;
  }));
}

std::vector<btSoftBody*> SkinnedSoftBody::Impl::pieces() const {
  std::vector<btSoftBody*> out;
  for (const auto& p : pieces_)
    if (p && p->body) out.push_back(p->body.get());
  return out;
}

std::int32_t SkinnedSoftBody::Impl::vertex_of(const btSoftBody* body, int node) const {
  for (const auto& p : pieces_)
    if (p && p->body && p->body.get() == body)
      return node >= 0 && std::size_t(node) < p->node_vertex.size()
                 ? p->node_vertex[std::size_t(node)]
                 : -1;
  return -1;
}

double SkinnedSoftBody::Impl::total_mass() const {
  double m = 0;
  for (const double x : mass_) m += x;
  return m;
}

Eigen::Vector3d SkinnedSoftBody::Impl::momentum() const {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  for (std::int32_t v = 0; v < vertex_count(); ++v)
    p += mass_[static_cast<std::size_t>(v)] * velocity(v);
  return p;
}

double SkinnedSoftBody::Impl::momentum_scale() const {
  double s = 0;
  for (std::int32_t v = 0; v < vertex_count(); ++v)
    s += mass_[static_cast<std::size_t>(v)] * velocity(v).norm();
  return s;
}

double SkinnedSoftBody::Impl::rest_length(std::int32_t u, std::int32_t v) const {
  const auto [a, b] = edge_key(u, v);
  const std::int32_t li = edge_link_.find(a, b);
  const std::int32_t p = piece_of_[static_cast<std::size_t>(a)];
  if (li < 0 || p < 0) return -1;
  return pieces_[static_cast<std::size_t>(p)]->rest[static_cast<std::size_t>(li)];
}

double SkinnedSoftBody::Impl::bending_rest_length(std::int32_t u, std::int32_t v) const {
  const auto [a, b] = edge_key(u, v);
  const std::int32_t li = bend_link_.find(a, b);
  const std::int32_t p = piece_of_[static_cast<std::size_t>(a)];
  if (li < 0 || p < 0) return -1;
  return pieces_[static_cast<std::size_t>(p)]->rest[static_cast<std::size_t>(li)];
}

std::int32_t SkinnedSoftBody::Impl::link_count() const {
  std::int32_t n = 0;
  for (const auto& p : pieces_)
    if (p && p->body) n += p->body->m_links.size() - p->bending;
  return n;
}

std::int32_t SkinnedSoftBody::Impl::bending_link_count() const {
  std::int32_t n = 0;
  for (const auto& p : pieces_)
    if (p) n += p->bending;
  return n;
}

PieceId SkinnedSoftBody::Impl::piece_of(std::int32_t vertex) const {
  if (vertex < 0 || vertex >= vertex_count())
    throw std::out_of_range("SkinnedSoftBody::piece_of: vertex " + std::to_string(vertex) +
                            " out of range [0, " + std::to_string(vertex_count()) + ")");
  const std::int32_t p = piece_of_[static_cast<std::size_t>(vertex)];
  return p < 0 ? PieceId{} : pieces_.id_of(p);
}

void SkinnedSoftBody::Impl::set_piece_collision(PieceId id, int group, int mask) {
  check_editable("set_piece_collision");
  Piece& piece = pieces_.live(id, "set_piece_collision");
  piece.settings.collision_group = group;
  piece.settings.collision_mask = mask;
  // Bullet reads the filter when it makes the broadphase proxy: out of the world and back in.
  link_.remove(piece.body.get());
  link_.add(piece.body.get(), group, mask);
}

void SkinnedSoftBody::Impl::check_editable(const char* what) const {
  if (link_.stepping && link_.stepping())
    throw std::logic_error(std::string("SkinnedSoftBody::") + what +
                           ": called inside stepSimulation (from a step hook or other code the "
                           "step runs); Bullet's contacts hold node pointers until the step "
                           "ends, so edit between stepSimulation calls");
  if (!pieces_.lost().empty())
    throw std::logic_error(std::string("SkinnedSoftBody::") + what + ": " + pieces_.lost());
}

// --- SkinnedSoftBody: forwards to its Impl ---

SkinnedSoftBody::SkinnedSoftBody(const WorldLink& link, const mesh::SkinnedMesh& mesh,
                                 const skin::Skeleton& skeleton, const Material& material,
                                 const PieceSettings& settings)
    : impl_(std::make_unique<Impl>(link, mesh, skeleton, material, settings)) {
  impl_->pieces_.drop_events();  // the pieces made here are listed by piece_ids(), not announced
}
SkinnedSoftBody::~SkinnedSoftBody() = default;

void SkinnedSoftBody::set_pose(const skin::Pose& pose) {
  impl_->set_pose(pose);
}
void SkinnedSoftBody::play(const skin::Animation& animation, skin::Blend blend, bool loop) {
  impl_->play(animation, blend, loop);
}
void SkinnedSoftBody::set_keyframes(skin::PoseTrack track, skin::Blend blend) {
  impl_->set_keyframes(std::move(track), blend);
}
void SkinnedSoftBody::set_pose_source(std::function<void(double, skin::Pose&)> source) {
  impl_->set_pose_source(std::move(source));
}
void SkinnedSoftBody::set_world_transform(const Eigen::Isometry3d& transform) {
  if (!transform.matrix().allFinite())
    throw std::invalid_argument("SkinnedSoftBody::set_world_transform: non-finite transform");
  const Eigen::Matrix3d r = transform.linear();
  if (!(r.transpose() * r).isIdentity(1e-9) || r.determinant() < 0)
    throw std::invalid_argument(
        "SkinnedSoftBody::set_world_transform: the linear part is not a rotation (a rigid "
        "transform is needed: scale the mesh instead)");
  impl_->drive_.set_transform(transform);
}
const Eigen::Isometry3d& SkinnedSoftBody::world_transform() const {
  return impl_->drive_.transform();
}
void SkinnedSoftBody::set_clock(const Clock& clock) {
  impl_->set_clock(clock);
}
double SkinnedSoftBody::clock_time() const {
  return impl_->clock_now_;
}
void SkinnedSoftBody::snap_to_pose() {
  impl_->snap_to_pose();
}
void SkinnedSoftBody::set_skin_threads(int threads) {
  impl_->set_skin_threads(threads);
}
void SkinnedSoftBody::set_pinned(std::span<const std::int32_t> vertices) {
  impl_->set_pinned(vertices);
}

mesh::CutResult SkinnedSoftBody::cut(const cga::Plane<double>& plane,
                                     const mesh::CutOptions& options) {
  auto result = impl_->cut(plane, options);
  impl_->pieces_.deliver();
  return result;
}
mesh::DrillResult SkinnedSoftBody::drill(const mesh::DrillTool& tool,
                                         const mesh::DrillOptions& options) {
  auto result = impl_->drill(tool, options);
  impl_->pieces_.deliver();
  return result;
}
void SkinnedSoftBody::begin_tear(const mesh::TearOptions& options) {
  impl_->begin_tear(options);
}
mesh::TearStep SkinnedSoftBody::tear_advance(const mesh::ScalpelSample& sample) {
  auto step = impl_->tear_advance(sample);
  impl_->pieces_.deliver();
  return step;
}
const mesh::Tear* SkinnedSoftBody::tear() const {
  return impl_->tear();
}
TearGrowthReport SkinnedSoftBody::grow_tear() {
  impl_->check_editable("grow_tear");
  return impl_->growth_.grow(*this, impl_->tear_.get());
}
double SkinnedSoftBody::tear_grown_length() const {
  return impl_->growth_.grown();
}
void SkinnedSoftBody::apply(const mesh::TopologyChange& change) {
  impl_->apply(change);
  impl_->pieces_.deliver();
}
const ApplyStats& SkinnedSoftBody::last_apply() const {
  return impl_->last_apply();
}

const mesh::SkinnedMesh& SkinnedSoftBody::mesh() const {
  return impl_->mesh();
}
const skin::Skeleton& SkinnedSoftBody::skeleton() const {
  return impl_->skeleton();
}
const Material& SkinnedSoftBody::material() const {
  return impl_->material();
}
const std::vector<std::string>& SkinnedSoftBody::material_warnings() const {
  return impl_->warnings_;
}
void SkinnedSoftBody::sync_mesh() {
  impl_->sync_mesh();
}
std::int32_t SkinnedSoftBody::vertex_count() const {
  return impl_->vertex_count();
}
const membrane::SolveReport& SkinnedSoftBody::last_solve() const {
  return impl_->membrane_.last_report();
}
std::int32_t SkinnedSoftBody::piece_count() const {
  return impl_->piece_count();
}
std::vector<btSoftBody*> SkinnedSoftBody::pieces() const {
  return impl_->pieces();
}
Eigen::Vector3d SkinnedSoftBody::position(std::int32_t vertex) const {
  return impl_->position(vertex);
}
Eigen::Vector3d SkinnedSoftBody::velocity(std::int32_t vertex) const {
  return impl_->velocity(vertex);
}
double SkinnedSoftBody::mass(std::int32_t vertex) const {
  return impl_->mass(vertex);
}
bool SkinnedSoftBody::kinematic(std::int32_t vertex) const {
  return impl_->kinematic(vertex);
}
btSoftBody* SkinnedSoftBody::body_of(std::int32_t vertex) const {
  return impl_->body_of(vertex);
}
std::int32_t SkinnedSoftBody::vertex_of(const btSoftBody* body, int node) const {
  return impl_->vertex_of(body, node);
}
std::int32_t SkinnedSoftBody::node_of(std::int32_t vertex) const {
  return impl_->node_of(vertex);
}
Eigen::Vector3d SkinnedSoftBody::target(std::int32_t vertex) const {
  return impl_->target(vertex);
}
double SkinnedSoftBody::total_mass() const {
  return impl_->total_mass();
}
Eigen::Vector3d SkinnedSoftBody::momentum() const {
  return impl_->momentum();
}
double SkinnedSoftBody::momentum_scale() const {
  return impl_->momentum_scale();
}
double SkinnedSoftBody::rest_length(std::int32_t u, std::int32_t v) const {
  return impl_->rest_length(u, v);
}
std::int32_t SkinnedSoftBody::link_count() const {
  return impl_->link_count();
}
std::int32_t SkinnedSoftBody::bending_link_count() const {
  return impl_->bending_link_count();
}
double SkinnedSoftBody::bending_rest_length(std::int32_t u, std::int32_t v) const {
  return impl_->bending_rest_length(u, v);
}
bool SkinnedSoftBody::detached(std::int32_t vertex) const {
  return impl_->detached(vertex);
}
std::int32_t SkinnedSoftBody::detached_count() const {
  return impl_->detached_count();
}

std::vector<PieceId> SkinnedSoftBody::piece_ids() const {
  return impl_->pieces_.ids();
}
bool SkinnedSoftBody::piece_valid(PieceId id) const {
  return impl_->pieces_.valid(id);
}
btSoftBody* SkinnedSoftBody::piece_body(PieceId id) const {
  return impl_->pieces_.body(id);
}
PieceId SkinnedSoftBody::piece_of(std::int32_t vertex) const {
  return impl_->piece_of(vertex);
}
void SkinnedSoftBody::on_piece_event(std::function<void(const PieceEvent&)> listener) {
  impl_->pieces_.listen(std::move(listener));
}
const PieceSettings& SkinnedSoftBody::piece_settings(PieceId id) const {
  return impl_->pieces_.settings(id);
}
void SkinnedSoftBody::set_piece_user(PieceId id, void* user) {
  impl_->pieces_.set_user(id, user);
}
void SkinnedSoftBody::set_piece_collision(PieceId id, int group, int mask) {
  impl_->set_piece_collision(id, group, mask);
}
void SkinnedSoftBody::release_piece(PieceId id, const ReleaseOptions& options) {
  impl_->release_piece(id, options);
}
bool SkinnedSoftBody::piece_released(PieceId id) const {
  return impl_->pieces_.released(id);
}

std::uint64_t SkinnedSoftBody::topology_version() const {
  return impl_->topology_version_;
}
std::span<const mesh::FaceTag> SkinnedSoftBody::face_tags() const {
  return impl_->mesh_.face_tags;
}
Eigen::Matrix3Xd SkinnedSoftBody::normals() const {
  return impl_->normals();
}
const skin::Pose& SkinnedSoftBody::pose() const {
  return impl_->drive_.pose();
}
std::vector<skin::Versor> SkinnedSoftBody::joint_transforms() const {
  return impl_->joint_transforms();
}
void SkinnedSoftBody::debug_draw(btIDebugDraw& drawer) const {
  impl_->debug_draw(drawer);
}

void SkinnedSoftBody::update(double dt, double time) {
  impl_->update(dt, time);
}
std::optional<NonFiniteNode> SkinnedSoftBody::first_non_finite_node() const {
  return impl_->first_non_finite_node();
}
void SkinnedSoftBody::skin_targets(double time) {
  impl_->skin_targets(time);
}

}  // namespace conform::bullet
