#include "kinds/character_edits.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

#include "conform/skin/pose.hpp"
#include "kinds/event_time.hpp"

namespace conform::scenes {

using Json = nlohmann::json;
using Vec3 = Eigen::Vector3d;

BindPose::BindPose(const mesh::SkinnedMesh& mesh) : positions(mesh.current) {
  if (positions.cols() == 0) return;
  lo = positions.rowwise().minCoeff();
  hi = positions.rowwise().maxCoeff();
  for (Eigen::Index v = 0; v < positions.cols(); ++v) {
    Eigen::Index slot = 0;
    mesh.weights.col(v).maxCoeff(&slot);
    dominant_bone.push_back(mesh.bones(slot, v));
  }
}

std::int32_t BindPose::bone_near(const Vec3& p) const {
  Eigen::Index nearest = 0;
  (positions.colwise() - p).colwise().squaredNorm().minCoeff(&nearest);
  return dominant_bone[static_cast<std::size_t>(nearest)];
}

BoneCarrier::BoneCarrier(const bullet::SkinnedSoftBody& body, const BindPose& bind,
                         const std::string& bone, const Vec3& near, const std::string& key)
    : body_(body) {
  const skin::Skeleton& sk = body.skeleton();
  bone_ = bone.empty() ? bind.bone_near(near) : sk.find_bone(bone);
  if (bone_ < 0)
    throw std::runtime_error("key '" + key + "', value \"" + bone + "\": no bone of that name (" +
                             std::to_string(sk.bone_count()) + " bones)");
  std::vector<skin::Versor> global(static_cast<std::size_t>(sk.joint_count()));
  skin::global_versors(sk, skin::Pose::rest(sk), global);
  const skin::Bone& b = sk.bones[static_cast<std::size_t>(bone_)];
  const auto inverse = (global[static_cast<std::size_t>(b.joint)] * b.offset).inverse();
  if (!inverse) throw std::runtime_error(key + ": bone " + b.name + " has no inverse bind versor");
  from_bind_ = *inverse;
}

skin::Versor BoneCarrier::versor() const {
  const skin::Bone& b = body_.skeleton().bones[static_cast<std::size_t>(bone_)];
  return body_.joint_transforms()[static_cast<std::size_t>(b.joint)] * b.offset;
}

Vec3 BoneCarrier::point(const Vec3& bind) const {
  return body_.world_transform() * Vec3((versor() * from_bind_).apply(bind));
}

Vec3 BoneCarrier::direction(const Vec3& at, const Vec3& d) const {
  return (point(at + d.normalized()) - point(at)).normalized();
}

double BoneCarrier::scale() const {
  return (versor() * from_bind_).scale;
}

const std::string& BoneCarrier::bone_name() const {
  return body_.skeleton().bones[static_cast<std::size_t>(bone_)].name;
}

namespace {
// cut.region: "nearest" (the section nearest cut.seed, by default cut.point) or "everywhere"
// (the unbounded plane).
void read_region(Reader& r, CutEdit& e) {
  const std::string region = r.text("region", "nearest", {"nearest", "everywhere"});
  e.region = region == "nearest" ? CutEdit::Region::nearest : CutEdit::Region::everywhere;
  e.seed = r.vec3("seed", e.point);
}
}  // namespace

CutEdit read_cut(Reader& root) {
  Reader r = root.object("cut");
  CutEdit e, d;
  e.enabled = r.boolean("enabled", d.enabled);
  e.at = r.number("at", d.at, 0, 1e5);
  e.bone = r.text("bone", d.bone);
  e.point = r.vec3("point", d.point);
  e.normal = r.vec3("normal", d.normal);
  if (!(e.normal.norm() > 1e-9)) r.fail("normal", Json{0, 0, 0}, "must not be zero");
  e.cap = r.boolean("cap", d.cap);
  read_region(r, e);
  e.sever = read_sever(r, d.sever);
  r.finish();
  return e;
}

TearEdit read_tear(Reader& root) {
  Reader r = root.object("tear");
  TearEdit e, d;
  e.enabled = r.boolean("enabled", d.enabled);
  e.at = r.number("at", d.at, 0, 1e5);
  e.duration = r.number("duration", d.duration, 0, 1e5);
  e.samples = r.integer("samples", d.samples, 2, 100000);
  e.bone = r.text("bone", d.bone);
  e.from = r.vec3("from", d.from);
  e.to = r.vec3("to", d.to);
  e.blade_a = r.vec3("blade_a", d.blade_a);
  e.blade_b = r.vec3("blade_b", d.blade_b);
  if ((e.blade_a - e.blade_b).norm() < 1e-9)
    r.fail("blade_b", Json{e.blade_b.x(), e.blade_b.y(), e.blade_b.z()},
           "the blade's two ends must differ");
  r.finish();
  return e;
}

DrillEdit read_drill(Reader& root) {
  Reader r = root.object("drill");
  DrillEdit e, d;
  e.enabled = r.boolean("enabled", d.enabled);
  e.at = r.number("at", d.at, 0, 1e5);
  e.bone = r.text("bone", d.bone);
  e.tip = r.vec3("tip", d.tip);
  e.base = r.vec3("base", d.base);
  if ((e.tip - e.base).norm() < 1e-9)
    r.fail("tip", Json{e.tip.x(), e.tip.y(), e.tip.z()}, "must differ from base");
  e.radius = r.number("radius", d.radius, 1e-5, 0.5);
  e.tube = r.boolean("tube", d.tube);
  r.finish();
  return e;
}

Json apply_cut(bullet::SkinnedSoftBody& body, const BindPose& bind, const CutEdit& edit) {
  const Vec3 p = bind.point(edit.point);
  const BoneCarrier carrier(body, bind, edit.bone, p, "cut.bone");
  const std::int32_t before = body.vertex_count(), pieces_before = body.piece_count();
  mesh::CutOptions options;
  options.cap = edit.cap;
  // The seed is carried by the cut's bone, like the plane, so it stays on the aimed limb.
  if (edit.region == CutEdit::Region::nearest)
    options.region = mesh::CutRegion::seed(carrier.point(bind.point(edit.seed)));
  const auto plane =
      cga::Plane<double>::from_normal_point(carrier.direction(p, edit.normal), carrier.point(p));
  const mesh::CutResult r = body.cut(plane, options);
  Json event = {{"status", r.status == mesh::CutStatus::Cut ? "cut" : "missed"},
                {"bone", carrier.bone_name()},
                {"crossed_edges", r.crossed_edges},
                {"new_vertices", body.vertex_count() - before},
                {"loops", r.loops},
                {"capped_loops", r.capped_loops},
                {"cap_faces", r.cap_faces},
                {"new_pieces", body.piece_count() - pieces_before},
                {"region", edit.region == CutEdit::Region::nearest ? "nearest" : "everywhere"}};
  if (edit.region == CutEdit::Region::nearest) {
    event["seed"] = {edit.seed.x(), edit.seed.y(), edit.seed.z()};
    event["sections"] = r.sections;  // where the plane meets the body
    event["kept_sections"] = r.kept_sections;
  }
  if (!r.message.empty()) event["message"] = r.message;
  return event;
}

void TearRun::advance(bullet::SkinnedSoftBody& body, double t, GeometricTear* copy) {
  for (; next_ < edit_.samples && event_due(t, edit_.time(next_)); ++next_) {
    const double u = edit_.samples > 1 ? double(next_) / (edit_.samples - 1) : 0.0;
    const Vec3 p = bind_.point((1 - u) * edit_.from + u * edit_.to);
    const BoneCarrier carrier(body, bind_, edit_.bone, bind_.point(edit_.from), "tear.bone");
    if (next_ == 0) body.begin_tear(), bone_ = carrier.bone_name();
    const mesh::ScalpelSample s{t, carrier.point(p + bind_.offset(edit_.blade_a)),
                                carrier.point(p + bind_.offset(edit_.blade_b))};
    extended_ += body.tear_advance(s).extended;
    if (copy) copy->advance(s);
    const mesh::Tear* tear = body.tear();
    if (next_ + 1 == edit_.samples && tear && tear->started()) {
      // Where the tear ends against where the blade ended: the segment's nearest point.
      const Vec3 tip = body.position(tear->right_border().back()), ab = s.b - s.a;
      const double u = std::clamp((tip - s.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      tip_to_blade_ = (s.a + u * ab - tip).norm();
    }
  }
}

Json TearRun::summary(const bullet::SkinnedSoftBody& body) const {
  const mesh::Tear* tear = body.tear();
  Json j = {{"bone", bone_},
            {"samples", next_},
            {"extending_samples", extended_},
            // The first sample starts the tear; every later one should extend it.
            {"extended_fraction", next_ > 1 ? double(extended_) / (next_ - 1) : 0.0},
            {"path_points", tear ? tear->path_length() : 0},
            {"length", tear ? tear->length() : 0.0},
            // The tip's distance from the last blade when it was applied, relative to the
            // bind pose's diagonal (−1: the tear never started).
            {"tip_to_last_blade_rel", tip_to_blade_ < 0 ? -1.0 : tip_to_blade_ / bind_.diagonal()}};
  if (tear && !tear->message().empty()) j["message"] = tear->message();
  return j;
}

Json apply_drill(bullet::SkinnedSoftBody& body, const BindPose& bind, const DrillEdit& edit) {
  const Vec3 tip = bind.point(edit.tip), base = bind.point(edit.base);
  const BoneCarrier carrier(body, bind, edit.bone, 0.5 * (tip + base), "drill.bone");
  const double radius = edit.radius * bind.diagonal() * carrier.scale();
  const std::int32_t before = body.vertex_count();
  mesh::DrillOptions options;
  options.tube = edit.tube;
  const mesh::DrillResult r =
      body.drill({carrier.point(tip), carrier.point(base), radius}, options);
  const double disc = std::numbers::pi * radius * radius;
  Json event = {{"status", r.holes > 0 ? "drilled" : "missed"},
                {"bone", carrier.bone_name()},
                {"radius", radius},
                {"holes", r.holes},
                {"tubes", r.tubes},
                {"rim_vertices", r.rim_vertices},
                {"new_vertices", body.vertex_count() - before},
                {"removed_area", r.removed_area},
                // The area removed per hole against the disc πr² (1 on a flat wall).
                {"area_per_hole_vs_disc", r.holes > 0 ? r.removed_area / (r.holes * disc) : 0.0},
                {"detached_vertices", body.detached_count()}};
  if (!r.message.empty()) event["message"] = r.message;
  return event;
}

namespace {

// Union-find over file vertices (path halving).
struct Pieces {
  std::vector<std::int32_t> parent;
  explicit Pieces(std::int32_t n) : parent(static_cast<std::size_t>(n)) {
    std::iota(parent.begin(), parent.end(), 0);
  }
  std::int32_t find(std::int32_t v) {
    while (parent[std::size_t(v)] != v)
      v = parent[std::size_t(v)] = parent[std::size_t(parent[std::size_t(v)])];
    return v;
  }
  void join(std::int32_t a, std::int32_t b) { parent[std::size_t(find(a))] = find(b); }
};

using RestKey = std::array<double, 3>;

// The file vertices grouped by rest position (groups of one left out), each sorted.
std::vector<std::vector<std::int32_t>> coincident_groups(const Eigen::Matrix3Xd& rest) {
  std::vector<std::int32_t> order(static_cast<std::size_t>(rest.cols()));
  std::iota(order.begin(), order.end(), 0);
  const auto key = [&](std::int32_t v) { return RestKey{rest(0, v), rest(1, v), rest(2, v)}; };
  std::sort(order.begin(), order.end(),
            [&](std::int32_t a, std::int32_t b) { return key(a) < key(b); });
  std::vector<std::vector<std::int32_t>> groups;
  for (std::size_t i = 0; i < order.size();) {
    std::size_t j = i + 1;
    while (j < order.size() && key(order[j]) == key(order[i])) ++j;
    if (j - i > 1)
      groups.emplace_back(order.begin() + std::ptrdiff_t(i), order.begin() + std::ptrdiff_t(j));
    i = j;
  }
  return groups;
}

}  // namespace

SeamGap::SeamGap(const Eigen::Matrix3Xd& rest, std::span<const mesh::Face> faces,
                 std::span<const std::int32_t> mesh_of, std::span<const std::int32_t> vertex_map) {
  const auto node = [&](std::int32_t v) {
    return vertex_map.empty() ? v : vertex_map[static_cast<std::size_t>(v)];
  };
  const std::vector<std::vector<std::int32_t>> groups = coincident_groups(rest);
  Pieces pieces(static_cast<std::int32_t>(rest.cols()));
  for (const mesh::Face& f : faces) pieces.join(f[0], f[1]), pieces.join(f[0], f[2]);
  std::vector<std::int32_t> first_of_node(static_cast<std::size_t>(rest.cols()), -1);
  for (std::int32_t v = 0; v < rest.cols(); ++v) {  // the weld's joins
    std::int32_t& first = first_of_node[static_cast<std::size_t>(node(v))];
    if (first < 0)
      first = v;
    else
      pieces.join(first, v);
  }
  for (const auto& g : groups)  // one position within one file mesh
    for (std::size_t k = 1; k < g.size(); ++k)
      if (mesh_of[std::size_t(g[k])] == mesh_of[std::size_t(g[0])]) pieces.join(g[0], g[k]);
  starts_.push_back(0);
  for (const auto& g : groups) {
    // One entry per file vertex, (piece, body vertex), sorted: a run of one piece is that
    // piece's copies of the position.
    std::vector<std::pair<std::int32_t, std::int32_t>> copies;
    for (const std::int32_t v : g) copies.emplace_back(pieces.find(v), node(v));
    std::sort(copies.begin(), copies.end());
    touching_ += copies.front().first != copies.back().first;
    for (std::size_t i = 0; i < copies.size();) {
      std::size_t j = i + 1;
      while (j < copies.size() && copies[j].first == copies[i].first) ++j;
      if (j - i > 1) {  // a seam: several file vertices of one piece at one rest position
        const std::size_t first = nodes_.size();
        for (std::size_t k = i; k < j; ++k)
          if (k == i || copies[k].second != copies[k - 1].second)
            nodes_.push_back(copies[k].second);
        open_ += nodes_.size() - first > 1;
        file_vertices_ += static_cast<std::int32_t>(j - i);
        starts_.push_back(static_cast<std::int32_t>(nodes_.size()));
      }
      i = j;
    }
  }
}

double SeamGap::measure(const bullet::SkinnedSoftBody& body) const {
  double worst = 0;
  for (std::size_t g = 0; g + 1 < starts_.size(); ++g)
    for (std::int32_t a = starts_[g]; a < starts_[g + 1]; ++a)
      for (std::int32_t b = a + 1; b < starts_[g + 1]; ++b) {
        const std::int32_t u = nodes_[static_cast<std::size_t>(a)],
                           w = nodes_[static_cast<std::size_t>(b)];
        if (body.detached(u) || body.detached(w)) continue;
        worst = std::max(worst, (body.position(u) - body.position(w)).norm());
      }
  return worst;
}

}  // namespace conform::scenes
