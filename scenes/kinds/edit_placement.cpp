#include "kinds/edit_placement.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "conform/mesh/cut.hpp"
#include "conform/mesh/drill.hpp"
#include "kinds/geometric_tear.hpp"
#include "kinds/surface_point.hpp"

namespace conform::scenes {

using Vec3 = Eigen::Vector3d;

namespace {

// Bones at or below `bone`'s joint (joints are sorted parents first).
std::vector<bool> bones_below(const skin::Skeleton& sk, std::int32_t bone) {
  std::vector<bool> below_joint(static_cast<std::size_t>(sk.joint_count()), false);
  const std::int32_t root = sk.bones[static_cast<std::size_t>(bone)].joint;
  for (std::int32_t j = 0; j < sk.joint_count(); ++j) {
    const std::int32_t parent = sk.joints[static_cast<std::size_t>(j)].parent;
    below_joint[std::size_t(j)] = j == root || (parent >= 0 && below_joint[std::size_t(parent)]);
  }
  std::vector<bool> below(sk.bones.size());
  for (std::size_t b = 0; b < sk.bones.size(); ++b)
    below[b] = below_joint[static_cast<std::size_t>(sk.bones[b].joint)];
  return below;
}

// The largest connected piece of the vertices `in` marks (joined by faces wholly among them):
// a limb is one piece of skin, not separate objects on one branch of the skeleton.
std::vector<std::int32_t> largest_piece(const BindPose& bind, const std::vector<bool>& in) {
  const auto n = static_cast<std::size_t>(bind.positions.cols());
  std::vector<std::int32_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  const auto find = [&](std::int32_t v) {
    while (parent[std::size_t(v)] != v)
      v = parent[std::size_t(v)] = parent[std::size_t(parent[std::size_t(v)])];
    return v;
  };
  for (const mesh::Face& f : bind.faces)
    if (in[std::size_t(f[0])] && in[std::size_t(f[1])] && in[std::size_t(f[2])])
      parent[std::size_t(find(f[1]))] = find(f[0]), parent[std::size_t(find(f[2]))] = find(f[0]);
  std::vector<std::int32_t> size(n, 0);
  for (std::size_t v = 0; v < n; ++v)
    if (in[v]) ++size[std::size_t(find(std::int32_t(v)))];
  const auto root = std::int32_t(std::max_element(size.begin(), size.end()) - size.begin());
  std::vector<std::int32_t> out;
  for (std::size_t v = 0; v < n; ++v)
    if (in[v] && find(std::int32_t(v)) == root) out.push_back(std::int32_t(v));
  return out;
}

std::vector<std::int32_t> limb_vertices(const BindPose& bind, const skin::Skeleton& sk,
                                        std::int32_t bone) {
  if (bone < 0) {  // the whole model, every piece of it
    std::vector<std::int32_t> all(static_cast<std::size_t>(bind.positions.cols()));
    std::iota(all.begin(), all.end(), 0);
    return all;
  }
  std::vector<bool> in(static_cast<std::size_t>(bind.positions.cols()));
  const std::vector<bool> below = bones_below(sk, bone);
  for (std::size_t v = 0; v < in.size(); ++v) {
    const std::int32_t b = bind.dominant_bone[v];
    in[v] = b >= 0 && below[static_cast<std::size_t>(b)];
  }
  return largest_piece(bind, in);
}

// The principal axes of the vertices (columns, largest variance last) and their variances.
Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> principal_axes(const BindPose& bind,
                                                              const std::vector<std::int32_t>& vs,
                                                              const Vec3& centre) {
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const std::int32_t v : vs) {
    const Vec3 d = bind.positions.col(v) - centre;
    cov += d * d.transpose();
  }
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov / double(vs.size()));
}

Vec3 centroid(const BindPose& bind, const std::vector<std::int32_t>& vs) {
  Vec3 c = Vec3::Zero();
  for (const std::int32_t v : vs) c += bind.positions.col(v);
  return c / double(vs.size());
}

// Where the bone's joint stands in the bind pose: its bind versor's origin, B⁻¹(0).
Vec3 joint_position(const skin::Skeleton& sk, std::int32_t bone, const Vec3& fallback) {
  if (bone < 0) return fallback;
  const auto inverse = sk.bones[static_cast<std::size_t>(bone)].offset.inverse();
  return inverse ? Vec3(inverse->apply(Vec3::Zero())) : fallback;
}

// The limb's extent along its axis and its median radius about it.
void measure_extent(const BindPose& bind, Limb& limb) {
  std::vector<double> radii;
  limb.from = limb.to = 0;
  for (const std::int32_t v : limb.vertices) {
    const Vec3 d = bind.positions.col(v) - limb.centre;
    const double t = d.dot(limb.axis);
    limb.from = std::min(limb.from, t), limb.to = std::max(limb.to, t);
    radii.push_back((d - t * limb.axis).norm());
  }
  std::nth_element(radii.begin(), radii.begin() + std::ptrdiff_t(radii.size() / 2), radii.end());
  limb.radius = radii[radii.size() / 2];
}

// The anchor of a blade crossing the skin at `s`, `reach` either side.
SkinAnchor anchor_at(const BindPose& bind, const SurfacePoint& s, double reach) {
  const mesh::Face& f = bind.faces[static_cast<std::size_t>(s.face)];
  const Vec3 a = bind.positions.col(f[0]), b = bind.positions.col(f[1]),
             c = bind.positions.col(f[2]);
  const Vec3 n = (b - a).cross(c - a);
  // Barycentric weights by the sub-triangles' signed areas.
  const Vec3 w{n.dot((c - b).cross(s.point - b)), n.dot((a - c).cross(s.point - c)),
               n.dot((b - a).cross(s.point - a))};
  return {f, w / n.squaredNorm(), reach, 0.5 * n.norm()};
}

// The limb's section at `along`, held by the rings of its vertices either side (each slab
// widened up to 30 % of the limb until it holds at least 2; an empty one takes the nearest
// vertex on its side) and by the skin point on its outward side.
SkinSection section_of(const BindPose& bind, const Limb& limb, double along) {
  SkinSection s;
  const double tau = limb.from + along * limb.length();
  const auto t_of = [&](std::int32_t v) {
    return (bind.positions.col(v) - limb.centre).dot(limb.axis) - tau;
  };
  for (double w = 0.08 * limb.length(); w <= 0.3 * limb.length(); w *= 1.5) {
    s.near_ring.clear(), s.far_ring.clear();
    for (const std::int32_t v : limb.vertices) {
      const double t = t_of(v);
      if (t >= -w && t < 0) s.near_ring.push_back(v);
      if (t >= 0 && t <= w) s.far_ring.push_back(v);
    }
    if (s.near_ring.size() >= 2 && s.far_ring.size() >= 2) break;
  }
  for (auto* ring : {&s.near_ring, &s.far_ring}) {
    if (!ring->empty()) continue;
    const double sign = ring == &s.near_ring ? -1 : 1;
    std::int32_t nearest = -1;
    for (const std::int32_t v : limb.vertices)
      if (sign * t_of(v) >= 0 && (nearest < 0 || std::abs(t_of(v)) < std::abs(t_of(nearest))))
        nearest = v;
    ring->push_back(nearest >= 0 ? nearest : limb.vertices.front());
  }
  const Vec3 outside = limb.at(along) + limb.side * (3 * limb.radius + 0.01 * limb.length());
  s.outer =
      anchor_at(bind, nearest_surface_point(bind.positions, bind.faces, limb.faces, outside), 0);
  s.flat = limb.flat;
  const auto bind_x = [&](std::int32_t v) { return Vec3(bind.positions.col(v)); };
  s.bind_size = s.at(bind_x).size;
  return s;
}

Section bind_section(const BindPose& bind, const SkinSection& s) {
  return s.at([&](std::int32_t v) { return Vec3(bind.positions.col(v)); });
}
}  // namespace

std::int32_t named_bone(const skin::Skeleton& sk, const std::string& name, const std::string& key) {
  if (name.empty()) return -1;
  const std::int32_t b = sk.find_bone(name);
  if (b < 0)
    throw std::runtime_error("key '" + key + "', value \"" + name + "\": no bone of that name (" +
                             std::to_string(sk.bone_count()) + " bones)");
  return b;
}

std::string limb_name(const skin::Skeleton& sk, std::int32_t bone) {
  return bone < 0 ? "(the whole model)" : sk.bones[static_cast<std::size_t>(bone)].name;
}

Limb limb_of(const BindPose& bind, const skin::Skeleton& sk, std::int32_t bone,
             const std::string& key) {
  Limb limb;
  limb.bone = bone;
  limb.vertices = limb_vertices(bind, sk, bone);
  if (limb.vertices.size() < 4)
    throw std::runtime_error(key + ": the limb of " + limb_name(sk, bone) + " holds " +
                             std::to_string(limb.vertices.size()) +
                             " vertices; aim at a larger one");
  limb.centre = centroid(bind, limb.vertices);
  const auto axes = principal_axes(bind, limb.vertices, limb.centre);
  limb.axis = axes.eigenvectors().col(2);
  // Away from the root joint: 0 at the limb's root end, 1 at its far end.
  const Vec3 root = joint_position(sk, bone, bind.positions.rowwise().mean());
  if ((limb.centre - root).dot(limb.axis) < 0) limb.axis = -limb.axis;
  const Eigen::Vector3d variance = axes.eigenvalues();
  limb.flat = variance(0) < 1e-4 * variance(1);
  measure_extent(bind, limb);
  // Outward: away from the model's centre across the axis; a sheet's side is its normal.
  const Vec3 away = limb.centre - Vec3(bind.positions.rowwise().mean());
  const Vec3 across = away - away.dot(limb.axis) * limb.axis;
  limb.side = limb.flat                            ? Vec3(axes.eigenvectors().col(0))
              : across.norm() > 0.25 * limb.radius ? across.normalized()
                                                   : Vec3(axes.eigenvectors().col(1));
  std::vector<bool> in(static_cast<std::size_t>(bind.positions.cols()), false);
  for (const std::int32_t v : limb.vertices) in[static_cast<std::size_t>(v)] = true;
  for (std::size_t f = 0; f < bind.faces.size(); ++f) {
    const mesh::Face& t = bind.faces[f];
    if (in[std::size_t(t[0])] || in[std::size_t(t[1])] || in[std::size_t(t[2])])
      limb.faces.push_back(static_cast<std::int32_t>(f));
  }
  return limb;
}

namespace {

// How many edges of the limb's faces lie on the mesh's border (one face), e.g. seams the
// import's weld left open.
std::int32_t border_edges(const BindPose& bind, const Limb& limb) {
  using Edge = std::pair<std::int32_t, std::int32_t>;
  const auto edge = [](const mesh::Face& f, int k) {
    const std::int32_t a = f[std::size_t(k)], b = f[std::size_t((k + 1) % 3)];
    return Edge{std::min(a, b), std::max(a, b)};
  };
  std::vector<Edge> all;
  for (const mesh::Face& f : bind.faces)
    for (int k = 0; k < 3; ++k) all.push_back(edge(f, k));
  std::sort(all.begin(), all.end());
  std::int32_t border = 0;
  for (const std::int32_t fi : limb.faces) {
    const mesh::Face& f = bind.faces[static_cast<std::size_t>(fi)];
    for (int k = 0; k < 3; ++k) {
      const auto [lo, hi] = std::equal_range(all.begin(), all.end(), edge(f, k));
      border += hi - lo == 1;
    }
  }
  return border;
}

}  // namespace

std::vector<std::int32_t> limb_candidates(const BindPose& bind, const skin::Skeleton& sk) {
  // Limbs, not the body and not slivers: between 1 % and 60 % of the vertices (at least 8).
  // First those whose skin is closed (no border edge: a tear's walk stops at a border), then
  // the elongated ones (principal spread over the next ≥ 2), then the thickest.
  const double n = double(bind.positions.cols());
  std::vector<std::pair<std::array<double, 3>, std::int32_t>> scored;
  for (std::int32_t b = 0; b < sk.bone_count(); ++b) {
    const double m = double(limb_vertices(bind, sk, b).size());
    if (m < std::max(8.0, 0.01 * n) || m > 0.6 * n) continue;
    const Limb limb = limb_of(bind, sk, b, "aim");
    const Eigen::Vector3d variance = principal_axes(bind, limb.vertices, limb.centre).eigenvalues();
    const bool elongated = variance(2) >= 4 * variance(1);
    scored.push_back({{double(border_edges(bind, limb) > 0), double(!elongated), -limb.radius}, b});
  }
  std::stable_sort(scored.begin(), scored.end(),
                   [](const auto& x, const auto& y) { return x.first < y.first; });
  std::vector<std::int32_t> out;
  for (const auto& s : scored) out.push_back(s.second);
  return out;
}

namespace {

// A copy of the model posed as the animation (none: the bind pose) has it at `t`.
void pose_copy(GeometricTear& copy, const skin::Skeleton& sk, const skin::Animation* animation,
               double t) {
  skin::Pose pose = skin::Pose::rest(sk);
  if (animation) animation->sample(sk, t, skin::Blend::log, pose);
  copy.repose(sk, pose, Eigen::Isometry3d::Identity());
}

// The limb's section at the cut's time closes as one capped loop.
bool trial_cut_caps(const mesh::SkinnedMesh& mesh, const skin::Skeleton& sk,
                    const skin::Animation* animation, const SkinSection& section,
                    const CutEdit& cut) {
  GeometricTear copy(mesh, mesh::TearOptions{});
  pose_copy(copy, sk, animation, cut.at);
  const Section s = section.at([&](std::int32_t v) { return Vec3(copy.mesh().current.col(v)); });
  mesh::CutOptions options;
  options.cap = true;
  options.region = mesh::CutRegion::seed(s.centre);
  const mesh::CutResult r = mesh::compute_cut(
      copy.mesh(), cga::Plane<double>::from_normal_point(s.axis, s.centre), options);
  return r.status == mesh::CutStatus::Cut && r.loops == 1 && r.capped_loops == 1;
}

// The fraction of the tear's later samples that extend it on the animated copy.
double trial_tear_extends(const mesh::SkinnedMesh& mesh, const skin::Skeleton& sk,
                          const skin::Animation* animation, const PlacedTear& at,
                          const TearEdit& tear) {
  GeometricTear copy(mesh, mesh::TearOptions{});
  int extended = 0;
  for (std::size_t i = 0; i < at.anchors.size(); ++i) {
    const double t = tear.time(static_cast<int>(i));
    pose_copy(copy, sk, animation, t);
    const auto [a, b] =
        at.anchors[i].blade([&](std::int32_t v) { return Vec3(copy.mesh().current.col(v)); });
    extended += copy.advance({t, a, b}).extended && i > 0;
  }
  return at.anchors.size() > 1 ? double(extended) / double(at.anchors.size() - 1) : 0.0;
}

// The drill lands (1), and makes its tube when asked (another 0.5).
double trial_drill_lands(const mesh::SkinnedMesh& mesh, const skin::Skeleton& sk,
                         const skin::Animation* animation, const PlacedDrill& at,
                         const DrillEdit& drill) {
  GeometricTear copy(mesh, mesh::TearOptions{});
  pose_copy(copy, sk, animation, drill.at);
  mesh::SkinnedMesh posed = copy.mesh();
  mesh::Adjacency adjacency(posed);
  const Section s = at.section.at([&](std::int32_t v) { return Vec3(posed.current.col(v)); });
  mesh::DrillOptions options;
  options.tube = drill.tube;
  const mesh::DrillResult r = mesh::drill(posed, adjacency, drill_through(at, s), options);
  return double(r.holes > 0) + 0.5 * double(drill.tube && r.tubes > 0);
}

}  // namespace

std::int32_t auto_aim(const mesh::SkinnedMesh& mesh, const BindPose& bind, const skin::Skeleton& sk,
                      const skin::Animation* animation, const CutEdit& cut, const TearEdit& tear,
                      const DrillEdit& drill) {
  // Tried on the skinned model without physics (as the geometric copy), in the candidates'
  // order: the best by a capped cut (one loop) and then by the fraction of the tear's samples
  // that extend it; the first of equals.
  std::int32_t best = -1;
  double best_score = -1;
  std::vector<std::int32_t> candidates = limb_candidates(bind, sk);
  candidates.push_back(-1);  // the whole model last
  for (const std::int32_t b : candidates) {
    const Limb limb = limb_of(bind, sk, b, "aim");
    TearEdit on_limb = tear;
    on_limb.on_limb = true, on_limb.bone.clear();
    DrillEdit drill_on_limb = drill;
    drill_on_limb.on_limb = true, drill_on_limb.bone.clear();
    const double score =
        double(trial_cut_caps(mesh, sk, animation, section_of(bind, limb, cut.along), cut)) +
        trial_tear_extends(mesh, sk, animation, place_tear(on_limb, bind, sk, b), on_limb) +
        trial_drill_lands(mesh, sk, animation, place_drill(drill_on_limb, bind, sk, b),
                          drill_on_limb);
    if (score > best_score) best = b, best_score = score;
  }
  return best;
}

namespace {

Limb aimed_limb(const BindPose& bind, const skin::Skeleton& sk, const std::string& bone,
                std::int32_t aim, const std::string& key) {
  return limb_of(bind, sk, bone.empty() ? aim : named_bone(sk, bone, key), key);
}

}  // namespace

PlacedCut place_cut(const CutEdit& e, const BindPose& bind, const skin::Skeleton& sk,
                    std::int32_t aim) {
  if (!e.on_limb)
    return {bind.point(e.point),
            e.normal,
            bind.point(e.seed),
            named_bone(sk, e.bone, "cut.bone"),
            "",
            {}};
  const Limb limb = aimed_limb(bind, sk, e.bone, aim, "cut.bone");
  // The limb's cross-section: the plane across its axis, the section nearest its centre.
  PlacedCut out;
  out.section = section_of(bind, limb, e.along);
  const Section s = bind_section(bind, out.section);
  out.point = out.seed = s.centre, out.normal = s.axis;
  out.limb = limb_name(sk, limb.bone);
  return out;
}

namespace {

PlacedTear tear_in_box(const TearEdit& e, const BindPose& bind, const skin::Skeleton& sk) {
  PlacedTear out;
  const std::int32_t named = named_bone(sk, e.bone, "tear.bone");
  const std::int32_t bone = named >= 0 ? named : bind.bone_near(bind.point(e.from));
  for (int i = 0; i < e.samples; ++i) {
    const double u = double(i) / (e.samples - 1);
    const Vec3 p = bind.point((1 - u) * e.from + u * e.to);
    out.blade_a.push_back(p + bind.offset(e.blade_a));
    out.blade_b.push_back(p + bind.offset(e.blade_b));
    out.bone.push_back(bone);
  }
  return out;
}

}  // namespace

PlacedTear place_tear(const TearEdit& e, const BindPose& bind, const skin::Skeleton& sk,
                      std::int32_t aim) {
  if (!e.on_limb) return tear_in_box(e, bind, sk);
  const Limb limb = aimed_limb(bind, sk, e.bone, aim, "tear.bone");
  PlacedTear out;
  out.limb = limb_name(sk, limb.bone);
  const double length = e.length > 0 ? e.length : 0.4 * limb.length();
  const Vec3 side = e.outer ? limb.side : Vec3(-limb.side);
  const double reach = e.depth * limb.radius;
  // Each sample: the skin point nearest a point well outside the limb on its side, the blade
  // crossing the skin there along its normal.
  for (int i = 0; i < e.samples; ++i) {
    const double along = e.along + length / limb.length() * double(i) / (e.samples - 1);
    const Vec3 outside = limb.at(along) + side * (3 * limb.radius + 0.01 * limb.length());
    const SurfacePoint s = nearest_surface_point(bind.positions, bind.faces, limb.faces, outside);
    out.anchors.push_back(anchor_at(bind, s, reach));
  }
  return out;
}

PlacedDrill place_drill(const DrillEdit& e, const BindPose& bind, const skin::Skeleton& sk,
                        std::int32_t aim) {
  if (!e.on_limb) {
    const Vec3 tip = bind.point(e.tip), base = bind.point(e.base);
    return {tip, base, e.radius * bind.diagonal(), named_bone(sk, e.bone, "drill.bone"), "", {}, 0};
  }
  const Limb limb = aimed_limb(bind, sk, e.bone, aim, "drill.bone");
  // Through the limb across its axis, away from the tear's side (a sheet: along its normal),
  // reaching past its farthest vertex that way.
  PlacedDrill out;
  out.section = section_of(bind, limb, e.along);
  const Section s = bind_section(bind, out.section);
  const Vec3 through = limb.flat ? s.side : Vec3(s.axis.cross(s.side).normalized());
  for (const std::int32_t v : limb.vertices)
    out.reach = std::max(out.reach, std::abs((bind.positions.col(v) - s.centre).dot(through)));
  // A sheet bends with the pose: its drill reaches a quarter of its length either side.
  out.reach = 1.5 * out.reach + limb.radius + (limb.flat ? 0.25 * limb.length() : 0.0);
  out.tip = s.centre + out.reach * through, out.base = s.centre - out.reach * through;
  out.radius = e.limb_radius * limb.radius;
  out.limb = limb_name(sk, limb.bone);
  return out;
}

}  // namespace conform::scenes
