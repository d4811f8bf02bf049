#include "conform/skin/procedural_arm.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

namespace conform::skin {
namespace {

using mesh::Face;
using mesh::kMaxInfluences;
using mesh::SkinnedMesh;

double smoothstep(double e0, double e1, double x) {
  const double u = std::clamp((x - e0) / (e1 - e0), 0.0, 1.0);
  return u * u * (3 - 2 * u);
}
double lerp(double a, double b, double u) {
  return a + (b - a) * u;
}

// The arm's cross-section at height z: an ellipse with half-axes (rx, ry). Radii are scaled
// with the segment lengths so that a longer arm stays arm-shaped.
struct Profile {
  double elbow, wrist, tip, shoulder_radius, tip_radius;

  // Mean radius of the open tube (no caps): a biceps bulge, a forearm bulge, a tapered wrist.
  double radius(double z) const {
    if (z <= elbow) {
      const double u = std::clamp(z / elbow, 0.0, 1.0);
      return lerp(shoulder_radius, 0.83 * shoulder_radius, u) +
             0.08 * shoulder_radius * std::sin(std::numbers::pi * u);
    }
    if (z <= wrist) {
      const double u = (z - elbow) / (wrist - elbow);
      return lerp(0.83 * shoulder_radius, 0.58 * shoulder_radius, u) +
             0.10 * shoulder_radius * std::sin(std::numbers::pi * u);
    }
    const double u = std::clamp((z - wrist) / (tip - wrist), 0.0, 1.0);
    return 0.58 * shoulder_radius * (1 + 0.25 * std::sin(std::numbers::pi * u));
  }
  // The hand is flattened (wider in x, thinner in y) past the wrist.
  double flatten(double z) const {
    return smoothstep(wrist - 0.6 * tip_radius, wrist + tip_radius, z);
  }
  // Rounded caps: a half-ellipsoid behind the shoulder and at the finger tips.
  double cap(double z) const {
    if (z < 0) {
      const double u = std::min(1.0, -z / shoulder_radius);
      return std::sqrt(std::max(0.0, 1 - u * u));
    }
    const double start = tip - tip_radius;
    if (z > start) {
      const double u = std::min(1.0, (z - start) / tip_radius);
      return std::sqrt(std::max(0.0, 1 - u * u));
    }
    return 1;
  }
  void half_axes(double z, double& rx, double& ry) const {
    const double r = radius(z) * cap(z);
    const double f = flatten(z);
    rx = r * (1 + 0.35 * f);
    ry = r * (1 - 0.45 * f);
  }
  double z_min() const { return -shoulder_radius; }
};

}  // namespace

Arm make_arm(int resolution) {
  ArmOptions o;
  o.resolution = resolution;
  return make_arm(o);
}

namespace {

// The ring heights at equal arc length along the meridian (z, mean radius) between the two
// poles, so that the caps get as many rings per centimetre as the tube: a fine polyline of
// the meridian, then inverse interpolation of its cumulative length.
std::vector<double> ring_heights(const Profile& p, int rings) {
  const int fine = std::max(20000, 8 * rings);
  std::vector<double> zs(static_cast<std::size_t>(fine) + 1), len(zs.size());
  auto mean_r = [&](double z) {
    double rx, ry;
    p.half_axes(z, rx, ry);
    return 0.5 * (rx + ry);
  };
  for (int i = 0; i <= fine; ++i) {
    // cosine spacing clusters samples at the poles, where the meridian is steep
    const double u = 0.5 - 0.5 * std::cos(std::numbers::pi * i / fine);
    zs[i] = lerp(p.z_min(), p.tip, u);
    len[i] = i == 0 ? 0.0
                    : len[i - 1] + std::hypot(zs[i] - zs[i - 1], mean_r(zs[i]) - mean_r(zs[i - 1]));
  }
  std::vector<double> ring_z(static_cast<std::size_t>(rings));
  std::size_t k = 0;
  for (int i = 0; i < rings; ++i) {
    const double s = len.back() * (i + 1) / (rings + 1);
    while (k + 1 < len.size() && len[k + 1] < s) ++k;
    const double u = (s - len[k]) / std::max(1e-300, len[k + 1] - len[k]);
    ring_z[i] = lerp(zs[k], zs[k + 1], u);
  }
  return ring_z;
}

// Rest positions (= current) and UVs: the south pole, the rings, the north pole.
void arm_vertices(const Profile& p, const std::vector<double>& ring_z, int segments,
                  Eigen::Index nv, SkinnedMesh& m) {
  const auto rings = static_cast<int>(ring_z.size());
  m.rest.resize(3, nv);
  m.uvs.resize(2, nv);
  m.rest.col(0) = Eigen::Vector3d(0, 0, p.z_min());
  m.uvs.col(0) = Eigen::Vector2d(0.5, 0);
  for (int i = 0; i < rings; ++i) {
    double rx, ry;
    p.half_axes(ring_z[i], rx, ry);
    for (int j = 0; j < segments; ++j) {
      const double phi = 2 * std::numbers::pi * j / segments;
      const Eigen::Index v = 1 + static_cast<Eigen::Index>(i) * segments + j;
      m.rest.col(v) = Eigen::Vector3d(rx * std::cos(phi), ry * std::sin(phi), ring_z[i]);
      m.uvs.col(v) = Eigen::Vector2d(static_cast<double>(j) / segments,
                                     static_cast<double>(i + 1) / (rings + 1));
    }
  }
  m.rest.col(nv - 1) = Eigen::Vector3d(0, 0, p.tip);
  m.uvs.col(nv - 1) = Eigen::Vector2d(0.5, 1);
  m.current = m.rest;
}

// Faces. Along a ring j runs counter-clockwise seen from +z, so (a, b, c) with b the next
// vertex around and c the next ring up has normal ∝ (b − a) × (c − a) ≈ φ̂ × ẑ = outward.
void arm_faces(int rings, int segments, Eigen::Index nv, SkinnedMesh& m) {
  auto idx = [segments](int ring, int seg) {
    return static_cast<std::int32_t>(1 + static_cast<long long>(ring) * segments +
                                     (seg % segments));
  };
  m.faces.reserve(static_cast<std::size_t>(2) * rings * segments);
  const auto south = 0, north = static_cast<std::int32_t>(nv - 1);
  for (int j = 0; j < segments; ++j) m.faces.push_back({south, idx(0, j + 1), idx(0, j)});
  for (int i = 0; i + 1 < rings; ++i)
    for (int j = 0; j < segments; ++j) {
      const std::int32_t a = idx(i, j), b = idx(i, j + 1), c = idx(i + 1, j + 1), d = idx(i + 1, j);
      m.faces.push_back({a, b, c});
      m.faces.push_back({a, c, d});
    }
  for (int j = 0; j < segments; ++j)
    m.faces.push_back({north, idx(rings - 1, j), idx(rings - 1, j + 1)});
}

// Area-weighted vertex normals.
void arm_normals(SkinnedMesh& m) {
  m.normals = Eigen::Matrix3Xd::Zero(3, m.rest.cols());
  for (const Face& f : m.faces) {
    const Eigen::Vector3d n =
        (m.rest.col(f[1]) - m.rest.col(f[0])).cross(m.rest.col(f[2]) - m.rest.col(f[0]));
    for (int k = 0; k < 3; ++k) m.normals.col(f[k]) += n;
  }
  m.normals.colwise().normalize();
}

// Weights: s_e rises from 0 to 1 across the elbow, s_w across the wrist;
// w_upper = 1 − s_e, w_fore = s_e (1 − s_w), w_hand = s_e s_w (sum 1, at most two non-zero
// while the transitions do not overlap). Sorted decreasing into the 4 slots.
void arm_weights(const Profile& p, const ArmOptions& o, SkinnedMesh& m) {
  const Eigen::Index nv = m.rest.cols();
  m.bones = Eigen::Matrix<std::int32_t, kMaxInfluences, Eigen::Dynamic>::Zero(kMaxInfluences, nv);
  m.weights = Eigen::Matrix<double, kMaxInfluences, Eigen::Dynamic>::Zero(kMaxInfluences, nv);
  for (Eigen::Index v = 0; v < nv; ++v) {
    const double z = m.rest(2, v);
    const double se = smoothstep(p.elbow - o.elbow_blend, p.elbow + o.elbow_blend, z);
    const double sw = smoothstep(p.wrist - o.wrist_blend, p.wrist + o.wrist_blend, z);
    std::array<std::pair<double, std::int32_t>, 3> w{
        {{1 - se, 0}, {se * (1 - sw), 1}, {se * sw, 2}}};
    std::stable_sort(w.begin(), w.end(), [](auto& a, auto& b) { return a.first > b.first; });
    int slot = 0;
    for (const auto& [weight, bone] : w)
      if (weight > 0) {
        m.bones(slot, v) = bone;
        m.weights(slot, v) = weight;
        ++slot;
      }
  }
}

// Skeleton: joints at the shoulder (origin), elbow and wrist along +z; each bone's offset is
// the inverse of its joint's bind placement (a translation by −z_joint).
void arm_skeleton(const Profile& p, Skeleton& sk) {
  const double joint_z[3] = {0, p.elbow, p.wrist};
  for (int j = 0; j < 3; ++j) {
    Joint joint;
    joint.name = kArmJointNames[j];
    joint.parent = j - 1;
    joint.rest = Versor::from_motor(cga::Motor<double>::from_translation(
        Eigen::Vector3d(0, 0, joint_z[j] - (j > 0 ? joint_z[j - 1] : 0.0))));
    sk.joints.push_back(joint);
    Bone bone;
    bone.name = kArmJointNames[j];
    bone.joint = j;
    bone.offset = Versor::from_motor(
        cga::Motor<double>::from_translation(Eigen::Vector3d(0, 0, -joint_z[j])));
    sk.bones.push_back(bone);
  }
}

}  // namespace

Arm make_arm(const ArmOptions& o) {
  if (!(o.upper_arm > 0) || !(o.forearm > 0) || !(o.hand > 0) || !(o.elbow_blend > 0) ||
      !(o.wrist_blend > 0))
    throw std::invalid_argument("make_arm: lengths and blend widths must be positive");
  if (o.segments <= 0 && o.resolution < 1)
    throw std::invalid_argument("make_arm: resolution must be at least 1");
  if (o.segments <= 0 && o.resolution > kMaxArmResolution)
    throw std::invalid_argument("make_arm: resolution " + std::to_string(o.resolution) +
                                " is more than the limit of " + std::to_string(kMaxArmResolution) +
                                " (" + std::to_string(kMaxArmVertices) + " vertices)");
  const int segments = o.segments > 0 ? o.segments : 32 * o.resolution;
  const int rings = o.rings > 0 ? o.rings : 80 * o.resolution;
  if (segments < 3 || rings < 2)
    throw std::invalid_argument("make_arm: need at least 3 segments and 2 rings");
  const long long vcount = static_cast<long long>(rings) * segments + 2;
  if (vcount > kMaxArmVertices)
    throw std::invalid_argument("make_arm: " + std::to_string(vcount) +
                                " vertices is more than the limit of " +
                                std::to_string(kMaxArmVertices) + " (that of resolution " +
                                std::to_string(kMaxArmResolution) + ")");

  const double scale = (o.upper_arm + o.forearm) / 0.55;  // 1 for the default arm
  const Profile p{o.upper_arm, o.upper_arm + o.forearm, o.upper_arm + o.forearm + o.hand,
                  0.048 * scale, std::min(0.025 * scale, 0.45 * o.hand)};
  Arm arm;
  const auto nv = static_cast<Eigen::Index>(vcount);
  arm_vertices(p, ring_heights(p, rings), segments, nv, arm.mesh);
  arm_faces(rings, segments, nv, arm.mesh);
  arm_normals(arm.mesh);
  arm_weights(p, o, arm.mesh);
  arm_skeleton(p, arm.skeleton);
  return arm;
}

}  // namespace conform::skin
