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

BindPose::BindPose(const mesh::SkinnedMesh& mesh) : positions(mesh.current), faces(mesh.faces) {
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
                         std::int32_t bone, const Vec3& near)
    : body_(body) {
  const skin::Skeleton& sk = body.skeleton();
  bone_ = bone < 0 ? bind.bone_near(near) : bone;
  std::vector<skin::Versor> global(static_cast<std::size_t>(sk.joint_count()));
  skin::global_versors(sk, skin::Pose::rest(sk), global);
  const skin::Bone& b = sk.bones[static_cast<std::size_t>(bone_)];
  const auto inverse = (global[static_cast<std::size_t>(b.joint)] * b.offset).inverse();
  if (!inverse) throw std::runtime_error("bone " + b.name + " has no inverse bind versor");
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

// The box's keys without its point (`box_key`) are refused on a limb; a limb's keys in the box
// (the scene's defaults hold them) are read and left unused.
void refuse_box_keys(Reader& r, bool on_limb, std::initializer_list<const char*> box_keys,
                     const char* box_key) {
  if (!on_limb) return;
  for (const char* k : box_keys)
    if (r.has(k))
      r.fail(k, nullptr,
             std::string("places the edit in the bounding box: give ") + box_key +
                 " too, or leave it out to aim at a limb");
}

// cut.region: "nearest" (the section nearest cut.seed, by default cut.point, or on a limb its
// axis point) or "everywhere" (the unbounded plane).
void read_region(Reader& r, CutEdit& e) {
  const std::string region = r.text("region", "nearest", {"nearest", "everywhere"});
  e.region = region == "nearest" ? CutEdit::Region::nearest : CutEdit::Region::everywhere;
  if (!e.on_limb) e.seed = r.vec3("seed", e.point);
}

}  // namespace

CutEdit read_cut(Reader& root) {
  Reader r = root.object("cut");
  CutEdit e, d;
  e.enabled = r.boolean("enabled", d.enabled);
  e.at = r.number("at", d.at, 0, 1e5);
  e.bone = r.text("bone", d.bone);
  e.on_limb = !r.has("point");
  refuse_box_keys(r, e.on_limb, {"normal", "seed"}, "cut.point");
  e.along = r.number("along", d.along, 0, 1);  // in the box: unused
  if (!e.on_limb) {
    e.point = r.vec3("point", d.point);
    e.normal = r.vec3("normal", d.normal);
    if (!(e.normal.norm() > 1e-9)) r.fail("normal", Json{0, 0, 0}, "must not be zero");
  }
  e.cap = r.boolean("cap", d.cap);
  read_region(r, e);
  e.sever = read_sever(r, d.sever);
  r.finish();
  return e;
}

namespace {
void read_tear_on_limb(Reader& r, TearEdit& e, const TearEdit& d) {
  e.along = r.number("along", d.along, 0, 1);
  e.length = r.number("length", d.length, 0, 1e3);
  e.outer = r.text("side", d.outer ? "outer" : "inner", {"outer", "inner"}) == "outer";
  e.depth = r.number("depth", d.depth, 0.01, 10);
}
void read_tear_in_box(Reader& r, TearEdit& e, const TearEdit& d) {
  e.from = r.vec3("from", d.from);
  e.to = r.vec3("to", d.to);
  e.blade_a = r.vec3("blade_a", d.blade_a);
  e.blade_b = r.vec3("blade_b", d.blade_b);
  if ((e.blade_a - e.blade_b).norm() < 1e-9)
    r.fail("blade_b", Json{e.blade_b.x(), e.blade_b.y(), e.blade_b.z()},
           "the blade's two ends must differ");
}
}  // namespace

TearEdit read_tear(Reader& root) {
  Reader r = root.object("tear");
  TearEdit e, d;
  e.enabled = r.boolean("enabled", d.enabled);
  e.at = r.number("at", d.at, 0, 1e5);
  e.duration = r.number("duration", d.duration, 0, 1e5);
  e.samples = r.integer("samples", d.samples, 2, 100000);
  e.bone = r.text("bone", d.bone);
  e.on_limb = !r.has("from");
  refuse_box_keys(r, e.on_limb, {"to", "blade_a", "blade_b"}, "tear.from");
  read_tear_on_limb(r, e, d);  // in the box: unused
  if (!e.on_limb) read_tear_in_box(r, e, d);
  r.finish();
  return e;
}

DrillEdit read_drill(Reader& root) {
  Reader r = root.object("drill");
  DrillEdit e, d;
  e.enabled = r.boolean("enabled", d.enabled);
  e.at = r.number("at", d.at, 0, 1e5);
  e.bone = r.text("bone", d.bone);
  e.on_limb = !r.has("tip");
  refuse_box_keys(r, e.on_limb, {"base", "radius"}, "drill.tip");
  e.along = r.number("along", d.along, 0, 1);  // in the box: unused
  e.limb_radius = r.number("radius_of_limb", d.limb_radius, 1e-3, 0.95);
  if (!e.on_limb) {
    e.tip = r.vec3("tip", d.tip);
    e.base = r.vec3("base", d.base);
    if ((e.tip - e.base).norm() < 1e-9)
      r.fail("tip", Json{e.tip.x(), e.tip.y(), e.tip.z()}, "must differ from base");
    e.radius = r.number("radius", d.radius, 1e-5, 0.5);
  }
  e.tube = r.boolean("tube", d.tube);
  r.finish();
  return e;
}

Json apply_cut(bullet::SkinnedSoftBody& body, const BindPose& bind, const PlacedCut& at,
               const CutEdit& edit) {
  const std::int32_t before = body.vertex_count(), pieces_before = body.piece_count();
  mesh::CutOptions options;
  options.cap = edit.cap;
  Vec3 point, normal, seed;
  std::string bone;
  if (at.section.near_ring.empty()) {
    // The plane and seed are carried by the cut's bone, so they stay on the aimed limb.
    const BoneCarrier carrier(body, bind, at.bone, at.point);
    point = carrier.point(at.point), normal = carrier.direction(at.point, at.normal);
    seed = carrier.point(at.seed), bone = carrier.bone_name();
  } else {  // the limb's section as the skin holds it now
    const Section s = at.section.now(body);
    point = seed = s.centre, normal = s.axis;
  }
  if (edit.region == CutEdit::Region::nearest) options.region = mesh::CutRegion::seed(seed);
  const mesh::CutResult r = body.cut(cga::Plane<double>::from_normal_point(normal, point), options);
  Json event = {{"status", r.status == mesh::CutStatus::Cut ? "cut" : "missed"},
                {"bone", bone},
                {"crossed_edges", r.crossed_edges},
                {"new_vertices", body.vertex_count() - before},
                {"loops", r.loops},
                {"capped_loops", r.capped_loops},
                {"cap_faces", r.cap_faces},
                {"new_pieces", body.piece_count() - pieces_before},
                {"region", edit.region == CutEdit::Region::nearest ? "nearest" : "everywhere"}};
  if (edit.on_limb) event["limb"] = at.limb, event["along"] = edit.along;
  if (edit.region == CutEdit::Region::nearest) {
    if (!edit.on_limb) event["seed"] = {edit.seed.x(), edit.seed.y(), edit.seed.z()};
    event["sections"] = r.sections;  // where the plane meets the body
    event["kept_sections"] = r.kept_sections;
  }
  if (!r.message.empty()) event["message"] = r.message;
  return event;
}

void TearRun::advance(bullet::SkinnedSoftBody& body, double t, GeometricTear* copy) {
  for (; next_ < edit_.samples && event_due(t, edit_.time(next_)); ++next_) {
    if (next_ == 0) body.begin_tear();
    const mesh::ScalpelSample s = sample(body, t);
    const bool extended = body.tear_advance(s).extended;
    extended_ += extended;
    if (!extended && next_ > 0)
      waits_.emplace_back(next_, body.tear() ? body.tear()->message() : "");
    // The copy takes the same stroke: in the box the same blade; on a limb the blade held by
    // its own skin, so that it owes nothing to the physics.
    if (copy) copy->advance(at_.anchors.empty() ? s : copy_sample(*copy, t));
    const mesh::Tear* tear = body.tear();
    if (next_ + 1 == edit_.samples && tear && tear->started()) {
      // Where the tear ends against where the blade ended: the segment's nearest point.
      const Vec3 tip = body.position(tear->right_border().back()), ab = s.b - s.a;
      const double u = std::clamp((tip - s.a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
      tip_to_blade_ = (s.a + u * ab - tip).norm();
    }
  }
}

mesh::ScalpelSample TearRun::sample(const bullet::SkinnedSoftBody& body, double t) {
  const auto i = static_cast<std::size_t>(next_);
  if (at_.anchors.empty()) {  // in the box: carried by one bone from the bind pose
    const BoneCarrier carrier(body, bind_, at_.bone[i], at_.blade_a[i]);
    if (next_ == 0) bone_ = carrier.bone_name();
    return {t, carrier.point(at_.blade_a[i]), carrier.point(at_.blade_b[i])};
  }
  // On the skin as it is now: the anchor's face crossed along its normal.
  const auto [a, b] = at_.anchors[i].blade(body);
  return {t, a, b};
}

mesh::ScalpelSample TearRun::copy_sample(const GeometricTear& copy, double t) const {
  const Eigen::Matrix3Xd& x = copy.mesh().current;
  const auto [a, b] = at_.anchors[static_cast<std::size_t>(next_)].blade(
      [&](std::int32_t v) { return Vec3(x.col(v)); });
  return {t, a, b};
}

Json TearRun::summary(const bullet::SkinnedSoftBody& body) const {
  const mesh::Tear* tear = body.tear();
  Json j = {{"bone", bone_},
            {"placement", edit_.on_limb ? "limb" : "box"},
            {"samples", next_},
            {"extending_samples", extended_},
            // The first sample starts the tear; every later one should extend it.
            {"extended_fraction", next_ > 1 ? double(extended_) / (next_ - 1) : 0.0},
            {"path_points", tear ? tear->path_length() : 0},
            {"length", tear ? tear->length() : 0.0},
            // The tip's distance from the last blade when it was applied, relative to the
            // bind pose's diagonal (−1: the tear never started).
            {"tip_to_last_blade_rel", tip_to_blade_ < 0 ? -1.0 : tip_to_blade_ / bind_.diagonal()}};
  if (edit_.on_limb) j["limb"] = at_.limb;
  if (tear && !tear->message().empty()) j["message"] = tear->message();
  j["waits"] = Json::array();  // each sample that did not extend it, and why
  for (const auto& [sample, why] : waits_) j["waits"].push_back({{"sample", sample}, {"why", why}});
  return j;
}

mesh::DrillTool drill_through(const PlacedDrill& at, const Section& s) {
  // Across the limb's axis and its outward side (a sheet: along its normal).
  const Vec3 through = at.section.flat ? s.side : Vec3(s.axis.cross(s.side).normalized());
  const double reach = at.reach * s.scale;
  return {s.centre + reach * through, s.centre - reach * through, at.radius * s.scale};
}

namespace {
// A vertex of the rings that hold the section is on a piece the cut released (fallen away).
bool section_released(const bullet::SkinnedSoftBody& body, const SkinSection& section) {
  for (const auto* ring : {&section.near_ring, &section.far_ring})
    for (const std::int32_t v : *ring)
      if (body.piece_released(body.piece_of(v))) return true;
  return false;
}
}  // namespace

Json apply_drill(bullet::SkinnedSoftBody& body, const BindPose& bind, const PlacedDrill& at,
                 const DrillEdit& edit) {
  Vec3 tip, base;
  double radius = 0;
  std::string bone;
  // In the box, or on a limb whose section a released piece took part of: carried by the
  // bone from the bind pose (on a limb, the dominant bone of the section's nearest vertex).
  const bool by_bone = at.section.near_ring.empty() || section_released(body, at.section);
  if (by_bone) {
    const BoneCarrier carrier(body, bind, at.bone, 0.5 * (at.tip + at.base));
    tip = carrier.point(at.tip), base = carrier.point(at.base);
    radius = at.radius * carrier.scale(), bone = carrier.bone_name();
  } else {  // through the limb's section as the skin holds it now
    const mesh::DrillTool tool = drill_through(at, at.section.now(body));
    tip = tool.tip, base = tool.base, radius = tool.radius;
  }
  const std::int32_t before = body.vertex_count();
  mesh::DrillOptions options;
  options.tube = edit.tube;
  const mesh::DrillResult r = body.drill({tip, base, radius}, options);
  const double disc = std::numbers::pi * radius * radius;
  Json event = {{"status", r.holes > 0 ? "drilled" : "missed"},
                {"bone", bone},
                {"radius", radius},
                {"holes", r.holes},
                {"tubes", r.tubes},
                {"rim_vertices", r.rim_vertices},
                {"new_vertices", body.vertex_count() - before},
                {"removed_area", r.removed_area},
                // The area removed per hole against the disc πr² (1 on a flat wall).
                {"area_per_hole_vs_disc", r.holes > 0 ? r.removed_area / (r.holes * disc) : 0.0},
                {"detached_vertices", body.detached_count()}};
  if (edit.on_limb)
    event["limb"] = at.limb, event["along"] = edit.along,
    event["held_by"] = by_bone ? "bone" : "skin";
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
