#include "conform/bullet/rigid_scalpel.hpp"

#include <BulletDynamics/Dynamics/btRigidBody.h>

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "conform/bullet/convert.hpp"

namespace conform::bullet {

namespace {

// A teleported blade is not swept face by face beyond this many sub-samples per update.
constexpr int kMaxSubSamples = 4096;

double segment_distance(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                        const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

// Whether segment (a, b) crosses triangle (p, q, r) (Möller–Trumbore, closed triangle).
bool crosses(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& p,
             const Eigen::Vector3d& q, const Eigen::Vector3d& r) {
  const Eigen::Vector3d d = b - a, e1 = q - p, e2 = r - p;
  const Eigen::Vector3d h = d.cross(e2);
  const double det = e1.dot(h);
  if (std::abs(det) < 1e-300) return false;
  const Eigen::Vector3d s = a - p;
  const double u = s.dot(h) / det;
  if (u < 0 || u > 1) return false;
  const Eigen::Vector3d k = s.cross(e1);
  const double v = d.dot(k) / det;
  if (v < 0 || u + v > 1) return false;
  const double t = e2.dot(k) / det;
  return t >= 0 && t <= 1;
}

}  // namespace

RigidScalpel::RigidScalpel(SkinnedSoftBody& body, const btRigidBody& blade,
                           const btVector3& a_local, const btVector3& b_local,
                           const Options& options)
    : body_(body),
      blade_(blade),
      a_local_(from_bt(a_local)),
      b_local_(from_bt(b_local)),
      options_(options) {
  std::ostringstream problem;
  if (!(std::isfinite(options.min_advance) && options.min_advance > 0))
    problem << "RigidScalpel: min_advance = " << options.min_advance << " must be finite and > 0";
  else if (!(std::isfinite(options.max_advance) && options.max_advance >= options.min_advance))
    problem << "RigidScalpel: max_advance = " << options.max_advance
            << " must be finite and ≥ min_advance (" << options.min_advance << ")";
  else if (!a_local_.allFinite() || !b_local_.allFinite() || !((a_local_ - b_local_).norm() > 0))
    problem << "RigidScalpel: the blade's end points (" << a_local_.transpose() << ") and ("
            << b_local_.transpose() << ") must be finite and distinct";
  if (!problem.str().empty()) throw std::invalid_argument(problem.str());
  measure_edges();
}

RigidScalpel::RigidScalpel(SkinnedSoftBody& body, const btRigidBody& blade,
                           const btVector3& a_local, const btVector3& b_local)
    : RigidScalpel(body, blade, a_local, b_local, Options{}) {}

// h: before the tear starts, the mean edge length of the mesh; after, of the faces at the tip,
// which are also kept as the tip's fan.
void RigidScalpel::measure_edges() {
  const auto& faces = body_.mesh().faces;
  double sum = 0;
  std::int64_t count = 0;
  fan_.clear();
  for (const auto& f : faces) {
    if (tip_ >= 0 && f[0] != tip_ && f[1] != tip_ && f[2] != tip_) continue;
    if (tip_ >= 0) fan_.push_back(f);
    for (int k = 0; k < 3; ++k)
      sum +=
          (body_.position(f[std::size_t(k)]) - body_.position(f[std::size_t((k + 1) % 3)])).norm();
    count += 3;
  }
  if (count > 0) edge_length_ = sum / double(count);
}

bool RigidScalpel::ready(const Eigen::Vector3d& a, const Eigen::Vector3d& b) const {
  if (tip_ < 0) return true;
  if (segment_distance(body_.position(tip_), a, b) < options_.min_advance * edge_length_)
    return false;
  for (const auto& f : fan_)
    if (crosses(a, b, body_.position(f[0]), body_.position(f[1]), body_.position(f[2])))
      return false;
  return true;
}

void RigidScalpel::submit(const mesh::ScalpelSample& sample, Update& update) {
  const mesh::TearStep step = body_.tear_advance(sample);
  ++update.samples;
  update.extended += step.extended;
  const mesh::Tear* tear = body_.tear();
  if (tear && tear->started()) {
    const std::int32_t tip = tear->right_border().back();
    if (tip != tip_) tip_ = tip, measure_edges();
  }
}

RigidScalpel::Update RigidScalpel::update(double time) {
  const btTransform& pose = blade_.getWorldTransform();
  const Eigen::Vector3d a1 = from_bt(pose * to_bt(a_local_)), b1 = from_bt(pose * to_bt(b_local_));
  Update update;
  if (first_) {
    first_ = false;
    body_.begin_tear(options_.tear);
    submit({time, a1, b1}, update);
  } else {
    const double move = std::max((a1 - a_).norm(), (b1 - b_).norm());
    const double longest = options_.max_advance * edge_length_;
    const int n =
        longest > 0 ? int(std::clamp(std::ceil(move / longest), 1.0, double(kMaxSubSamples))) : 1;
    for (int k = 1; k <= n; ++k) {
      const double s = double(k) / n;
      const mesh::ScalpelSample sample{time_ + s * (time - time_), a_ + s * (a1 - a_),
                                       b_ + s * (b1 - b_)};
      if (ready(sample.a, sample.b))
        submit(sample, update);
      else
        ++update.held;
    }
  }
  a_ = a1, b_ = b1, time_ = time;
  totals_.samples += update.samples;
  totals_.extended += update.extended;
  totals_.held += update.held;
  return update;
}

}  // namespace conform::bullet
