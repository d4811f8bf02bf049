#include "kinds/falling_pieces.hpp"

#include <BulletSoftBody/btSoftBody.h>
#include <btBulletDynamicsCommon.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <utility>

namespace conform::scenes {

GroundSettings read_ground(Reader& root, const GroundSettings& defaults) {
  GroundSettings s = defaults;
  if (root.is_boolean("ground")) {
    s.enabled = root.boolean("ground", defaults.enabled);
    return s;
  }
  Reader r = root.object("ground");
  s.enabled = r.boolean("enabled", defaults.enabled);
  if (r.has("height") || !std::isnan(defaults.height))
    s.height = r.number("height", defaults.height, -1e4, 1e4);
  r.finish();
  return s;
}

Json ground_summary(const GroundSettings& ground) {
  Json j = {{"enabled", ground.enabled}};
  if (ground.enabled) j["height_m"] = ground.height;
  return j;
}

SeverSettings read_sever(Reader& cut, const SeverSettings& defaults) {
  SeverSettings s;
  s.release = cut.boolean("release", defaults.release);
  s.volume_modulus = cut.number("volume_modulus", defaults.volume_modulus, 0, 1e9);
  return s;
}

Ground::Ground(SoftWorld& world, double height, const Eigen::Vector3d& centre, double size)
    : world_(world), height_(height) {
  // As thick as the model: a piece cut at the model's feet starts at the ground's top, and a
  // node inside a thin box can be pushed out through its bottom (a 2 cm glTF model's piece
  // fell through a box 0.1 of its size thick).
  const double half_height = size;
  shape_ = std::make_unique<btBoxShape>(
      btVector3(btScalar(size), btScalar(half_height), btScalar(size)));
  btTransform at;
  at.setIdentity();
  at.setOrigin(
      btVector3(btScalar(centre.x()), btScalar(height - half_height), btScalar(centre.z())));
  body_ = std::make_unique<btRigidBody>(
      btRigidBody::btRigidBodyConstructionInfo(0, nullptr, shape_.get()));
  body_->setWorldTransform(at);
  world.world.addRigidBody(body_.get(), kGroup, kGroup);
  world.world.getWorldInfo().m_sparsesdf.setDefaultVoxelsz(btScalar(size / 100));
  world.world.getWorldInfo().m_sparsesdf.Reset();
}

void Ground::fit_contact_grid(double piece_size) {
  // The grid resolves a piece of a tenth of its size (a 5 cm piece sank into a box at 0.25 m
  // and held at 0.025 m); a model's diagonal can be far larger than its severed limb.
  btSparseSdf<3>& sdf = world_.world.getWorldInfo().m_sparsesdf;
  const btScalar voxel = btScalar(piece_size / 10);
  if (!(voxel > 0) || voxel >= sdf.m_defaultVoxelsz) return;
  sdf.setDefaultVoxelsz(voxel);
  sdf.Reset();
}

Ground::~Ground() {
  world_.world.removeRigidBody(body_.get());
}

void FallingPieces::before_cut(const bullet::SkinnedSoftBody& body) {
  piece_before_.resize(static_cast<std::size_t>(body.vertex_count()));
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    piece_before_[static_cast<std::size_t>(v)] = body.piece_of(v);
}

namespace {
double extent(const btSoftBody& body) {
  btVector3 lo(BT_LARGE_FLOAT, BT_LARGE_FLOAT, BT_LARGE_FLOAT), hi = -lo;
  for (int i = 0; i < body.m_nodes.size(); ++i)
    lo.setMin(body.m_nodes[i].m_x), hi.setMax(body.m_nodes[i].m_x);
  return body.m_nodes.size() > 0 ? double((hi - lo).length()) : 0;
}

// Closed: every edge of its faces is shared by exactly two faces. Bullet's getVolume of an
// open surface depends on where it is; a capped cut of a model with other openings is open.
bool closed(const btSoftBody& body) {
  std::map<std::pair<const void*, const void*>, int> edges;
  for (int f = 0; f < body.m_faces.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      const void* a = body.m_faces[f].m_n[k];
      const void* b = body.m_faces[f].m_n[(k + 1) % 3];
      ++edges[std::minmax(a, b)];
    }
  return !edges.empty() &&
         std::all_of(edges.begin(), edges.end(), [](const auto& e) { return e.second == 2; });
}
}  // namespace

Json FallingPieces::release_severed(bullet::SkinnedSoftBody& body, double volume_modulus,
                                    Ground* ground) {
  // Each piece now: the piece its old vertices were in before the cut, and its size.
  struct Part {
    bullet::PieceId id, parent;
    std::int32_t vertices = 0;
  };
  std::vector<Part> parts;
  for (const bullet::PieceId id : body.piece_ids()) parts.push_back({id, {}, 0});
  auto part_of = [&](bullet::PieceId id) {
    return std::find_if(parts.begin(), parts.end(), [&](const Part& p) { return p.id == id; });
  };
  for (std::int32_t v = 0; v < body.vertex_count(); ++v) {
    const auto part = part_of(body.piece_of(v));
    if (part == parts.end()) continue;  // a detached vertex
    ++part->vertices;
    if (static_cast<std::size_t>(v) < piece_before_.size())
      part->parent = piece_before_[static_cast<std::size_t>(v)];
  }
  Json released = Json::array();
  for (const Part& p : parts) {
    // The largest part of its parent stays; a parent that was not split has one part.
    const bool largest = std::none_of(parts.begin(), parts.end(), [&](const Part& q) {
      return q.parent == p.parent && !(q.id == p.id) &&
             (q.vertices > p.vertices || (q.vertices == p.vertices && q.id.index < p.id.index));
    });
    if (largest || body.piece_released(p.id)) continue;
    const btSoftBody& piece = *body.piece_body(p.id);  // the body stays while the piece lives
    const double size = extent(piece);
    if (ground) ground->fit_contact_grid(size);
    // A contact margin of at most a twentieth of the piece: the scenes' 5 mm crushed a 2 mm
    // piece of a 3.7 cm model (WusonSMD.smd taken at 100 units a metre) inside out.
    btCollisionShape& shape = *body.piece_body(p.id)->getCollisionShape();
    shape.setMargin(std::min(shape.getMargin(), btScalar(size / 20)));
    const double volume = closed(piece) ? double(piece.getVolume()) : 0.0;
    bullet::ReleaseOptions options{};
    options.volume_modulus = volume > 0 ? volume_modulus : 0;
    body.release_piece(p.id, options);
    // Bullet's contacts with static bodies take kKHR (0.1 by default) of the penetration per
    // iteration: a resting piece sank 8 mm into the ground (13 mm past its margin) on huesitos.
    body.piece_body(p.id)->m_cfg.kKHR = 1;
    // A membrane body runs with Bullet's kDP = 0 (its damping is the membrane's). Undamped, in
    // either skin, huesitos' severed limb keeps the spin it lands with, and a node driven deep
    // into the ground loses its contact there: the piece falls through (docs/scenes.md). With a
    // ground, the links' damping at least (0.01 lands it within 1 mm); kDP damps the fall too,
    // so a piece without ground falls freely.
    btScalar& damping = body.piece_body(p.id)->m_cfg.kDP;
    if (ground) damping = std::max(damping, btScalar(0.01));
    if (ground)
      body.set_piece_collision(p.id, btBroadphaseProxy::DefaultFilter | Ground::kGroup,
                               btBroadphaseProxy::AllFilter);
    Fallen f;
    f.id = p.id;
    f.nodes = piece.m_nodes.size();
    f.volume_at_release = std::max(volume, 0.0);
    measure_one(piece, f, ground ? ground->height() : 0);
    f.com_y_at_release = f.com_y;
    pieces_.push_back(f);
    released.push_back({{"vertices", p.vertices},
                        {"closed", volume > 0},
                        {"volume_m3", std::max(volume, 0.0)},
                        {"volume_modulus", options.volume_modulus},
                        {"margin_m", double(shape.getMargin())}});
  }
  if (ground) ground_ = ground->height();
  return released;
}

void FallingPieces::measure_one(const btSoftBody& body, Fallen& f, double ground) {
  btVector3 com(0, 0, 0), momentum(0, 0, 0);
  btScalar mass = 0, lowest = BT_LARGE_FLOAT;
  for (int i = 0; i < body.m_nodes.size(); ++i) {
    const btSoftBody::Node& n = body.m_nodes[i];
    const btScalar m = n.m_im > 0 ? 1 / n.m_im : 0;
    com += n.m_x * m, momentum += n.m_v * m, mass += m;
    lowest = std::min(lowest, n.m_x.y());
  }
  if (mass > 0) com /= mass, momentum /= mass;
  f.com_y = double(com.y());
  f.speed = double(momentum.length());
  f.lowest = double(lowest) - ground;
  f.volume = f.volume_at_release > 0 ? double(body.getVolume()) : 0;
}

void FallingPieces::measure(const bullet::SkinnedSoftBody& body, const Ground* ground) {
  if (pieces_.empty()) return;
  lowest_ = std::numeric_limits<double>::infinity();
  for (Fallen& f : pieces_) {
    if (!body.piece_valid(f.id)) continue;
    measure_one(*body.piece_body(f.id), f, ground ? ground->height() : 0);
    lowest_ = std::min(lowest_, f.lowest);
  }
}

Json FallingPieces::summary() const {
  Json pieces = Json::array();
  for (const Fallen& f : pieces_) {
    Json p = {{"nodes", f.nodes},
              {"fall_m", f.com_y_at_release - f.com_y},
              {"speed_end_m_per_s", f.speed},
              {std::isnan(ground_) ? "lowest_y_end_m" : "lowest_above_ground_end_m", f.lowest}};
    if (f.volume_at_release > 0)
      p["volume_kept_end"] = f.volume / f.volume_at_release;  // V_end / V_release
    pieces.push_back(p);
  }
  return pieces;
}

Plot falling_plot(const std::string& scene, bool ground, double cut_at) {
  Plot plot("falling", scene + ": the pieces the cut severed", "time [s]",
            ground ? "lowest node above the ground [m]" : "lowest node's y [m]",
            {{"metrics.csv", "t", "released_lowest_m", "released pieces", "lines"}});
  plot.events = {{cut_at, "cut, released"}};
  return plot;
}

}  // namespace conform::scenes
