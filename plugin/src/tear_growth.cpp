#include "tear_growth.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "conform/bullet/skinned_soft_body.hpp"
#include "conform/membrane/crack_extension.hpp"
#include "conform/membrane/crack_growth.hpp"
#include "conform/mesh/topology_change.hpp"
#include "phase_clock.hpp"

namespace conform::bullet {
namespace {

void require(bool ok, const char* field, double value, const char* range) {
  if (ok) return;
  std::ostringstream out;
  out << "SkinnedSoftBody: material growth." << field << " = " << value << " is out of range ("
      << range << ")";
  throw std::invalid_argument(out.str());
}

// The crack's direction at the end `chain[0]` of a border chain, in the sheet's plane, away from
// the tear: the chord from the first chain vertex at least `length` behind the end (or the far
// end). The blade's last crossing may lie a fraction of an element behind its tip, at any angle.
Eigen::Vector3d end_direction(const mesh::SkinnedMesh& mesh, const std::vector<std::int32_t>& chain,
                              double length) {
  const Eigen::Vector3d end = mesh.rest.col(chain[0]);
  std::size_t k = 1;
  while (k + 1 < chain.size() && (mesh.rest.col(chain[k]) - end).norm() < length) ++k;
  const Eigen::Vector3d normal = membrane::sheet_normal(mesh, chain[0]);
  Eigen::Vector3d d = end - mesh.rest.col(chain[k]);
  d -= d.dot(normal) * normal;
  return d.normalized();
}

// The simulated positions in the rest frame around `at`: the rigid transform that best maps the
// skinned targets of the vertices within `radius` (rest) onto their rest positions (Umeyama,
// no scale) applied to every position. The energy does not change under it; the lips'
// displacement correlation then reads opening and sliding in the rest frame's n and e.
Eigen::Matrix3Xd rest_frame_positions(const SkinnedSoftBody& body, const mesh::SkinnedMesh& mesh,
                                      const Eigen::Vector3d& at, double radius) {
  std::vector<std::int32_t> near;
  for (std::int32_t v = 0; v < mesh.vertex_count(); ++v)
    if ((mesh.rest.col(v) - at).norm() <= radius && !body.detached(v)) near.push_back(v);
  Eigen::Matrix3Xd from(3, Eigen::Index(near.size())), to(3, Eigen::Index(near.size()));
  for (std::size_t i = 0; i < near.size(); ++i) {
    from.col(Eigen::Index(i)) = body.target(near[i]);
    to.col(Eigen::Index(i)) = mesh.rest.col(near[i]);
  }
  const Eigen::Matrix4d t = Eigen::umeyama(from, to, false);
  return (t.topLeftCorner<3, 3>() * mesh.current).colwise() +
         Eigen::Vector3d(t.topRightCorner<3, 1>());
}

std::vector<std::uint8_t> fixed_vertices(const SkinnedSoftBody& body) {
  std::vector<std::uint8_t> fixed(std::size_t(body.vertex_count()));
  for (std::int32_t v = 0; v < body.vertex_count(); ++v)
    fixed[std::size_t(v)] = body.kinematic(v) || body.detached(v);
  return fixed;
}

}  // namespace

void TearGrowthSettings::validate() const {
  require(std::isfinite(domain_radius) && domain_radius > 0, "domain_radius", domain_radius,
          "> 0 m");
  require(inner_fraction >= 0 && inner_fraction < 1, "inner_fraction", inner_fraction, "[0, 1)");
  require(snap_fraction >= 0 && snap_fraction < 0.5, "snap_fraction", snap_fraction, "[0, 0.5)");
}

const mesh::SkinnedMesh& TearGrowth::skin_mesh(const SkinnedSoftBody& body) const {
  return own_view_ ? view_ : body.mesh();
}

void TearGrowth::take_view(const SkinnedSoftBody& body) {
  const Eigen::Ref<const Eigen::Matrix3Xd> rest = skin_rest_();
  own_view_ = rest.data() != body.mesh().rest.data();
  if (!own_view_) return;
  view_ = body.mesh();
  view_.rest = rest;
}

void TearGrowth::follow_tear(const SkinnedSoftBody& body) {
  const mesh::Tear* tear = body.tear();
  if (tear != tear_) grown_ = 0;
  if (tear == tear_ && tear->path_length() == tear_points_) return;
  tear_ = tear, tear_points_ = tear->path_length();
  std::vector<std::int32_t> border = tear->right_border();
  const double chord = 0.5 * body.material().growth.domain_radius;
  const mesh::SkinnedMesh& mesh = skin_mesh(body);
  const Eigen::Vector3d start = end_direction(mesh, border, chord);
  std::reverse(border.begin(), border.end());
  const Eigen::Vector3d tip = end_direction(mesh, border, chord);
  tips_ = {{{border.back(), start}}, {{border.front(), tip}}};
}

TipGrowth TearGrowth::judge(const SkinnedSoftBody& body, const std::vector<std::uint8_t>& fixed,
                            std::size_t i) {
  const mesh::SkinnedMesh& mesh = skin_mesh(body);
  const TearGrowthSettings& s = body.material().growth;
  const membrane::CrackTip& tip = tips_[i].crack;
  const Eigen::Vector3d at = mesh.rest.col(tip.vertex);
  double radius = membrane::tip_domain_radius(mesh, fixed, tip.vertex, s.domain_radius);
  for (const Tip& other : tips_)  // the domain holds no other tip
    if (other.crack.vertex != tip.vertex)
      radius = std::min(radius, 0.5 * (mesh.rest.col(other.crack.vertex) - at).norm());
  membrane::EnergyReleaseOptions options;
  options.domain_radius = radius;
  options.inner_fraction = s.inner_fraction;
  const membrane::TipFracture f = membrane::energy_release(
      mesh, body.material().skin, rest_frame_positions(body, mesh, at, radius), tip, options);
  TipGrowth out;
  out.vertex = tip.vertex;
  out.energy_release_rate = f.energy_release_rate;
  out.k1 = f.k1, out.k2 = f.k2;
  out.domain_radius = radius;
  out.kink = membrane::mts_kink_angle(f.k1, f.k2);
  return out;
}

void TearGrowth::extend(SkinnedSoftBody& body, mesh::Tear& tear, std::size_t i, TipGrowth& judged) {
  Tip& tip = tips_[i];
  const mesh::SkinnedMesh& mesh = skin_mesh(body);
  const Eigen::Vector3d along = membrane::growth_direction(mesh, tip.crack, judged.kink);
  const membrane::CrackExtension ext = membrane::crack_extension(
      mesh, fixed_vertices(body), tip.crack.vertex, along, body.material().growth.snap_fraction);
  if (ext.change.empty()) {
    judged.message = ext.message;
    tip.stopped = judged.stopped = ext.reached_border;
    return;
  }
  const Eigen::Vector3d from = mesh.rest.col(tip.crack.vertex);
  body.apply(ext.change);
  if (own_view_) mesh::apply(view_, ext.change);  // as the body's mesh and its bind pose grew
  tear.adopt_growth(tip.crack.vertex, ext.duplicate, ext.new_tip);
  tear_points_ = tear.path_length();
  const Eigen::Vector3d to = skin_mesh(body).rest.col(ext.new_tip);
  judged.extended = (to - from).norm();
  tip.crack = {ext.new_tip, (to - from) / judged.extended};
  grown_ += judged.extended;
}

TearGrowthReport TearGrowth::grow(SkinnedSoftBody& body, mesh::Tear* tear) {
  TearGrowthReport report;
  const Material& m = body.material();
  if (!m.growth.enabled || m.model != MaterialModel::membrane || !tear || tear->path_length() < 2)
    return report;
  const double start = thread_seconds();
  body.sync_mesh();
  take_view(body);
  follow_tear(body);
  // Every running tip is judged on the same state before any of them grows.
  const std::vector<std::uint8_t> fixed = fixed_vertices(body);
  std::vector<std::size_t> running;
  for (std::size_t i = 0; i < tips_.size(); ++i)
    if (!tips_[i].stopped) running.push_back(i);
  for (const std::size_t i : running) report.tips.push_back(judge(body, fixed, i));
  for (std::size_t k = 0; k < running.size(); ++k) {
    TipGrowth& judged = report.tips[k];
    if (judged.energy_release_rate < m.skin.toughness) continue;
    extend(body, *tear, running[k], judged);
    report.grown += judged.extended;
  }
  report.seconds = thread_seconds() - start;
  return report;
}

}  // namespace conform::bullet
