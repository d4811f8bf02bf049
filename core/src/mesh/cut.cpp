#include "conform/mesh/cut.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <stdexcept>

#include "conform/cga/point.hpp"
#include "conform/mesh/detail/cut_predicates.hpp"
#include "conform/mesh/detail/union_find.hpp"
#include "oriented_sections.hpp"
#include "quad_split.hpp"

namespace conform::mesh {

using detail::Predicates;

namespace {

// The plane scaled to a unit normal; throws on a non-finite or zero normal.
cga::Plane<double> unit_plane(const cga::Plane<double>& plane) {
  const Eigen::Vector3d n = plane.normal();
  const double len = n.norm();
  if (!std::isfinite(len) || !std::isfinite(plane.distance()) || !(len > 0))
    throw std::invalid_argument(
        "cut: the plane must have a finite, non-zero normal and a finite distance");
  return cga::Plane<double>::from_normal_distance(n / len, plane.distance() / len);
}

struct Pending {
  Face v;    // after the separation remap
  Face pre;  // before it (original and crossing-vertex ids)
  std::int8_t side;
  std::int32_t original;  // the face it re-indexes, or −1 for a piece of a split face
  bool remapped = false;
};

// compute_cut's working arrays, kept per thread between calls so that a cut at haptic rates
// allocates only what it returns.
struct Scratch {
  std::vector<double> dist;
  std::vector<std::int8_t> side;
  std::vector<std::uint8_t> code;
  std::vector<std::int32_t> work, crossed, evaluate, again, snapped_now, parent, xcopy,
      plane_vertices, copy_plus, copy_minus, next, starts, ids, loop, section_parent, section_of;
  EdgeMap crossing;
  std::vector<Eigen::Vector3d> xpos;
  std::vector<Pending> pending;
  std::vector<std::pair<std::int32_t, std::int32_t>> on_plane;
  std::vector<std::array<std::int32_t, 3>> pending_local;
  std::vector<std::uint8_t> ambiguous, visited, diagonal;
  std::vector<std::uint64_t> plus_edges;
  std::vector<std::int32_t> unsnappable;  // sorted: vertices step 2 must not snap (pinches)
};
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

}  // namespace

namespace detail {

void classify_vertices(const SkinnedMesh& mesh, const cga::Plane<double>& plane_in,
                       Predicates predicates, std::vector<double>& distance) {
  const cga::Plane<double> plane = unit_plane(plane_in);
  const Eigen::Index nv = mesh.current.cols();
  distance.resize(static_cast<std::size_t>(nv));
  if (predicates == Predicates::Cga) {
    // X·Π with X = up(x): x·n − d (the ½x² e∞ and e0 parts meet Π's e∞ and zero e0).
    for (Eigen::Index i = 0; i < nv; ++i)
      distance[static_cast<std::size_t>(i)] =
          dot(cga::Point<double>::up(Eigen::Vector3d(mesh.current.col(i))), plane);
  } else {
    const Eigen::Vector3d n = plane.normal();
    const double d = plane.distance();
    for (Eigen::Index i = 0; i < nv; ++i)
      distance[static_cast<std::size_t>(i)] = n.dot(mesh.current.col(i)) - d;
  }
}

}  // namespace detail

namespace {

// One planar cut (Algorithm 1, steps 1–5 of cut.hpp) over the per-thread scratch arrays.
// Each step is one member; the state they hand on is the members below.
class CutComputation {
 public:
  CutComputation(const SkinnedMesh& mesh, const cga::Plane<double>& plane,
                 const CutOptions& options, Predicates predicates)
      : mesh_(mesh),
        plane_(unit_plane(plane)),
        options_(options),
        predicates_(predicates),
        sc_(scratch()),
        nv0_(mesh.vertex_count()),
        nf0_(mesh.face_count()),
        snap_(options.snap_fraction),
        floor_sin2_(std::sin(options.min_angle) * std::sin(options.min_angle)) {}

  CutResult run() {
    check_input();
    measure_distances();
    result_.change.base_vertex_count = nv0_;
    result_.change.edit = EditKind::cut;
    result_.change.base_face_count = nf0_;
    if (nf0_ == 0) return std::move(result_);
    eps_ = options_.plane_tolerance * diagonal_;
    if (!(reach_pos_ > eps_) || !(reach_neg_ > eps_)) {
      // Every vertex on one side or on the plane: only faces lying in the plane could
      // separate, and they go to the side of the material (opposite their normal), i.e. the
      // same side.
      result_.message = "the plane does not cross the mesh";
      return std::move(result_);
    }
    classify_sides();
    find_work_faces();
    snap();
    if (outside_work_) add_faces_around_far_snaps();
    if (options_.region.shape != CutRegion::Shape::everywhere && !select_sections()) {
      result_.message = "the plane crosses the mesh only in sections outside the region";
      return std::move(result_);
    }
    if (!split_crossed_faces()) {
      result_.change.new_vertices.clear();
      result_.crossed_edges = 0;
      result_.message = "the plane only touches the mesh";
      return std::move(result_);
    }
    separate_fans();
    separate_crossings();
    emit_faces();
    result_.status = CutStatus::Cut;
    if (options_.cap) cap();
    return std::move(result_);
  }

 private:
  void check_input() const {
    if (!(options_.snap_fraction >= 0 && options_.snap_fraction < 0.5) ||
        !(options_.plane_tolerance >= 0) || !(options_.min_angle >= 0 && options_.min_angle < 0.5))
      throw std::invalid_argument(
          "cut: snap_fraction must be in [0, 0.5), plane_tolerance ≥ 0 and min_angle in [0, "
          "0.5)");
    if (mesh_.current.cols() != nv0_)
      throw std::invalid_argument("cut: the current positions must be finite, one per vertex");
    if (const std::string problem = options_.region.validate(); !problem.empty())
      throw std::invalid_argument(problem);
  }

  // Step 1, in one pass over the positions: finite, their bounding box (the tolerance's
  // scale), the signed distances (the same predicates as classify_vertices) and the farthest
  // vertex on each side.
  void measure_distances() {
    std::vector<double>& dist = sc_.dist;
    dist.resize(static_cast<std::size_t>(nv0_));
    if (nv0_ == 0) return;
    const std::int32_t nv0 = nv0_;
    const double* x = mesh_.current.data();
    double lo[3] = {x[0], x[1], x[2]}, hi[3] = {x[0], x[1], x[2]};
    double reach_pos = 0, reach_neg = 0;
    bool finite = true;
    auto pass = [&](auto distance) {
      for (std::int32_t i = 0; i < nv0; ++i, x += 3) {
        for (int k = 0; k < 3; ++k) {
          finite &= std::isfinite(x[k]);
          lo[k] = std::min(lo[k], x[k]), hi[k] = std::max(hi[k], x[k]);
        }
        const double s = distance(x);
        dist[static_cast<std::size_t>(i)] = s;
        reach_pos = std::max(reach_pos, s), reach_neg = std::max(reach_neg, -s);
      }
    };
    const cga::Plane<double>& plane = plane_;
    if (predicates_ == Predicates::Cga) {
      pass([&](const double* p) {
        return dot(cga::Point<double>::up(Eigen::Vector3d(p[0], p[1], p[2])), plane);
      });
    } else {
      const Eigen::Vector3d n = plane.normal();
      const double d = plane.distance();
      pass([&](const double* p) { return n.x() * p[0] + n.y() * p[1] + n.z() * p[2] - d; });
    }
    if (!finite)
      throw std::invalid_argument("cut: the current positions must be finite, one per vertex");
    diagonal_ = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                          (hi[2] - lo[2]) * (hi[2] - lo[2]));
    reach_pos_ = reach_pos, reach_neg_ = reach_neg;
  }

  // Step 1's sides, and which vertices step 2 may snap. A vertex at distance d of the plane is
  // snapped only across an edge to a vertex at distance d' on the other side with
  // |d| < snap / (1 − snap) · |d'|, so only vertices nearer than that to the plane, measured
  // with the other side's reach, can be: "near". Per vertex code: 1 on the plane, 2 positive,
  // 8 negative, + 16 when near.
  void classify_sides() {
    const double eps = eps_;
    const double k_snap = snap_ / (1 - snap_) * (1 + 1e-9);  // a margin for rounding
    const double near_pos = k_snap * reach_neg_, near_neg = k_snap * reach_pos_;
    const std::vector<double>& dist = sc_.dist;
    std::vector<std::int8_t>& side = sc_.side;
    std::vector<std::uint8_t>& code = sc_.code;
    side.resize(static_cast<std::size_t>(nv0_));
    code.resize(static_cast<std::size_t>(nv0_));
    for (std::int32_t i = 0; i < nv0_; ++i) {
      const double s = dist[static_cast<std::size_t>(i)];
      const std::int8_t si = s > eps ? 1 : (s < -eps ? -1 : 0);
      side[static_cast<std::size_t>(i)] = si;
      code[static_cast<std::size_t>(i)] = static_cast<std::uint8_t>(
          (si == 0  ? 1
           : si > 0 ? 2
                    : 8) |
          ((si > 0 && s < near_pos) || (si < 0 && -s < near_neg) ? 16 : 0));
    }
  }

  // One pass over the faces: index check, and the faces that need work — crossed, touching
  // the plane, or with a near vertex (which snapping may put on the plane) — in increasing
  // order. The rest only tell which sides have faces.
  void find_work_faces() {
    const auto nf = static_cast<std::size_t>(nf0_);
    const Face* const faces = mesh_.faces.data();
    const std::uint8_t* const cd = sc_.code.data();
    std::vector<std::int32_t>& work = sc_.work;
    work.clear();
    work.reserve(256);
    int any = 0;
    const auto bound = static_cast<std::uint32_t>(nv0_);
    for (std::size_t fi = 0; fi < nf; ++fi) {
      const Face& f = faces[fi];
      const auto a = static_cast<std::uint32_t>(f[0]), b = static_cast<std::uint32_t>(f[1]),
                 c = static_cast<std::uint32_t>(f[2]);
      if ((a >= bound) | (b >= bound) | (c >= bound))
        throw std::invalid_argument("cut: face index out of range");
      const int fc = cd[a] | cd[b] | cd[c];
      if (fc == 2 || fc == 8) {  // strictly on one side, no vertex near the plane
        any |= fc;
        continue;
      }
      work.push_back(static_cast<std::int32_t>(fi));
    }
    face_pos_ = (any & 2) != 0, face_neg_ = (any & 8) != 0;
  }

  Eigen::Map<const Eigen::Vector3d> point(std::int32_t v) const {
    return Eigen::Vector3d::Map(mesh_.current.data() + 3 * std::size_t(v));
  }
  double dist(std::int32_t v) const { return sc_.dist[static_cast<std::size_t>(v)]; }
  // Where the plane crosses edge (u, w), from its lower vertex.
  Eigen::Vector3d crossing_point(std::int32_t u, std::int32_t w) const {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    const double da = dist(a), db = dist(b);
    const double t = da / (da - db);
    return (1 - t) * point(a) + t * point(b);
  }
  double crossing_t(std::int32_t from, std::int32_t to) const {  // from `from` along the edge
    const double df = dist(from), dt = dist(to);
    return df / (df - dt);
  }
  static bool is_crossed(const std::int8_t* s) {
    return s[0] * s[1] < 0 || s[1] * s[2] < 0 || s[2] * s[0] < 0;
  }
  // The split of face f with sides s (crossed): the quality (smallest angle's sin²) of its
  // worst triangle, or −1 when a crossing falls within `snap` of an edge's end; for a lone
  // vertex, `first_diagonal` tells how its quad is split (as step 3 will).
  double split_quality(const Face& f, const std::int8_t* s, bool* first_diagonal) const {
    const double snap = snap_;
    int zero = -1;
    for (int k = 0; k < 3; ++k)
      if (s[k] == 0) zero = k;
    if (zero >= 0) {
      const std::int32_t v0 = f[zero], v1 = f[(zero + 1) % 3], v2 = f[(zero + 2) % 3];
      const double t = crossing_t(v1, v2);
      if (t < snap || t > 1 - snap) return -1.0;
      const Eigen::Vector3d x = crossing_point(v1, v2);
      return std::min(smallest_angle_sin2(point(v0), point(v1), x),
                      smallest_angle_sin2(point(v0), x, point(v2)));
    }
    int lone = 0;
    for (int k = 0; k < 3; ++k)
      if (s[(k + 1) % 3] == s[(k + 2) % 3]) lone = k;
    const std::int32_t v0 = f[lone], v1 = f[(lone + 1) % 3], v2 = f[(lone + 2) % 3];
    const double t01 = crossing_t(v0, v1), t02 = crossing_t(v0, v2);
    if (t01 < snap || t01 > 1 - snap || t02 < snap || t02 > 1 - snap) return -1.0;
    const Eigen::Vector3d x01 = crossing_point(v0, v1), x20 = crossing_point(v2, v0);
    const Eigen::Vector3d p0 = point(v0), p1 = point(v1), p2 = point(v2);
    const QuadSplit quad = best_quad_split(
        x01, p1, p2, x20,
        [](const auto& a, const auto& b, const auto& c) { return smallest_angle_sin2(a, b, c); });
    if (first_diagonal) *first_diagonal = quad.first_diagonal;
    return std::min(smallest_angle_sin2(p0, x01, x20), quad.quality);
  }

  // Step 2, snapping, face by face: a crossed face whose split (by the vertices' current
  // sides) would make a triangle with smallest angle below its bound — min(min_angle, half the
  // face's smallest angle) — or whose crossing lies within snap_fraction of an edge's end, has
  // one vertex taken as on the plane: of the vertices whose snapping makes this face
  // acceptable (the lone vertex always does), the nearest to the plane. Snapping only uncrosses
  // faces, so the faces a snap touched are evaluated again until none snaps. Vertices never
  // move.
  void snap() {
    const Face* const faces = mesh_.faces.data();
    const std::int8_t* const sd = sc_.side.data();
    std::vector<std::int32_t>&crossed = sc_.crossed, &evaluate = sc_.evaluate, &again = sc_.again,
    &snapped_now = sc_.snapped_now;
    crossed.clear(), evaluate.clear(), again.clear(), snapped_now.clear();
    for (const std::int32_t fi : sc_.work) {
      const Face& f = faces[fi];
      const std::int8_t s[3] = {sd[f[0]], sd[f[1]], sd[f[2]]};
      if (is_crossed(s)) crossed.push_back(fi);
    }
    sc_.diagonal.assign(crossed.size(), 1);
    for (std::size_t i = 0; i < crossed.size(); ++i)
      evaluate.push_back(static_cast<std::int32_t>(i));
    while (!evaluate.empty()) {
      snapped_now.clear();
      for (const std::int32_t ci : evaluate) snap_face(ci);
      // Faces touched by this round's snaps that are still crossed: evaluate them again.
      std::sort(snapped_now.begin(), snapped_now.end());
      again.clear();
      if (!snapped_now.empty())
        for (std::size_t ci = 0; ci < crossed.size(); ++ci) {
          const Face& f = faces[crossed[ci]];
          bool touched = false;
          for (auto v : f) touched |= std::binary_search(snapped_now.begin(), snapped_now.end(), v);
          const std::int8_t s[3] = {sd[f[0]], sd[f[1]], sd[f[2]]};
          if (touched && is_crossed(s)) again.push_back(static_cast<std::int32_t>(ci));
        }
      evaluate.swap(again);
    }
  }

  // Step 2 for the ci-th crossed face: records its quad's diagonal, and snaps the fewest of
  // its vertices, nearest the plane, that make it acceptable.
  void snap_face(std::int32_t ci) {
    const Face& f =
        mesh_.faces[static_cast<std::size_t>(sc_.crossed[static_cast<std::size_t>(ci)])];
    std::int8_t* const sd = sc_.side.data();
    std::int8_t s[3] = {sd[f[0]], sd[f[1]], sd[f[2]]};
    if (!is_crossed(s)) return;
    bool first_diagonal = true;
    const double quality = split_quality(f, s, &first_diagonal);
    sc_.diagonal[static_cast<std::size_t>(ci)] = first_diagonal;
    if (quality >= floor_sin2_) return;  // the bound is never above the floor
    const double bound =
        sliver_bound_sin2(point(f[0]), point(f[1]), point(f[2]), options_.min_angle);
    if (quality >= bound) return;
    // Taking two of its vertices as on the plane always makes the face acceptable (it is no
    // longer crossed), so the nearest alone if that suffices, else the second nearest alone
    // if that does, else both.
    // A vertex a snap would pinch (compute_cut's later rounds) is never taken: it sorts last,
    // and the face keeps its sliver when only such vertices would do.
    const std::vector<std::int32_t>& barred = sc_.unsnappable;
    auto snappable = [&](int k) {
      return barred.empty() || !std::binary_search(barred.begin(), barred.end(), f[k]);
    };
    int order[3] = {0, 1, 2};
    std::sort(order, order + 3, [&](int i, int j) {
      const double di = s[i] == 0 ? -1 : snappable(i) ? std::abs(dist(f[i])) : INFINITY;
      const double dj = s[j] == 0 ? -1 : snappable(j) ? std::abs(dist(f[j])) : INFINITY;
      return di < dj || (di == dj && i < j);
    });
    const int first = s[order[0]] == 0 ? 1 : 0;  // skip a vertex already on the plane
    if (!snappable(order[first])) return;
    auto acceptable_without = [&](int k) {
      const std::int8_t keep = s[k];
      s[k] = 0;
      const bool ok = !is_crossed(s) || split_quality(f, s, nullptr) >= bound;
      s[k] = keep;
      return ok;
    };
    auto snap_vertex = [&](std::int32_t v) {
      sd[v] = 0;
      ++result_.snapped_vertices;
      sc_.snapped_now.push_back(v);
      if (!(sc_.code[static_cast<std::size_t>(v)] & 16)) outside_work_ = true;
    };
    const bool second = first == 0 && snappable(order[1]);
    if (acceptable_without(order[first])) {
      snap_vertex(f[order[first]]);
    } else if (second && acceptable_without(order[1])) {
      snap_vertex(f[order[1]]);
    } else {
      snap_vertex(f[order[first]]);
      if (second) snap_vertex(f[order[1]]);
    }
  }

  // Rare (a crossing far along its edge, in a poorly shaped face): a vertex step 1 did not flag
  // near was snapped; the faces around it, not in work, are found by one more pass.
  void add_faces_around_far_snaps() {
    std::vector<std::int32_t>& work = sc_.work;
    const std::uint8_t* const cd = sc_.code.data();
    const std::int8_t* const sd = sc_.side.data();
    const auto before = work.size();
    for (std::size_t fi = 0; fi < static_cast<std::size_t>(nf0_); ++fi) {
      const Face& f = mesh_.faces[fi];
      const int fc = cd[f[0]] | cd[f[1]] | cd[f[2]];
      if (!(fc == 2 || fc == 8)) continue;  // already in work
      if (sd[f[0]] == 0 || sd[f[1]] == 0 || sd[f[2]] == 0)
        work.push_back(static_cast<std::int32_t>(fi));
    }
    std::inplace_merge(work.begin(), work.begin() + static_cast<std::ptrdiff_t>(before),
                       work.end());
  }

  // A work face crossed by the plane or touching it (a section's face).
  bool in_section(const Face& f) const {
    const std::int8_t* const sd = sc_.side.data();
    const std::int8_t s[3] = {sd[f[0]], sd[f[1]], sd[f[2]]};
    return s[0] == 0 || s[1] == 0 || s[2] == 0 || is_crossed(s);
  }

  // The region's whole sections (cut_region.hpp), after step 2 so that snapped vertices count
  // as on the plane: the section faces grouped by shared vertices, each group's points (its
  // crossing points and vertices on the plane) measured against the region, and the work list
  // cut down to the kept groups' faces. Sharing any vertex is a coarser grouping than sharing a
  // crossed edge or a fan vertex, so no fan or crossing vertex is ever split between a kept and
  // a dropped face. False when no kept section crosses the plane.
  bool select_sections() {
    const CutRegion& region = options_.region;
    const std::int8_t* const sd = sc_.side.data();
    std::vector<std::int32_t>& parent = sc_.section_parent;
    parent.resize(static_cast<std::size_t>(nv0_));
    std::iota(parent.begin(), parent.end(), 0);
    for (const std::int32_t fi : sc_.work) {
      const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
      if (!in_section(f)) continue;
      detail::unite(parent.data(), f[0], f[1]);
      detail::unite(parent.data(), f[0], f[2]);
    }
    struct Section {
      std::int32_t points = 0, inside = 0;
      bool crossed = false;
      double nearest = std::numeric_limits<double>::infinity();  // squared, to region.center
    };
    std::vector<Section> sections;
    std::vector<std::int32_t>& section_of = sc_.section_of;  // by root vertex
    section_of.assign(static_cast<std::size_t>(nv0_), -1);
    auto measure = [&](Section& s, const Eigen::Vector3d& x) {
      ++s.points;
      s.inside += region.contains(x);
      s.nearest = std::min(s.nearest, (x - region.center).squaredNorm());
    };
    for (const std::int32_t fi : sc_.work) {
      const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
      if (!in_section(f)) continue;
      std::int32_t& id =
          section_of[static_cast<std::size_t>(detail::find_root(parent.data(), f[0]))];
      if (id < 0) id = static_cast<std::int32_t>(sections.size()), sections.emplace_back();
      Section& s = sections[static_cast<std::size_t>(id)];
      for (int k = 0; k < 3; ++k) {
        const std::int32_t v = f[k], w = f[(k + 1) % 3];
        if (sd[v] == 0) measure(s, point(v));
        if (sd[v] * sd[w] < 0) measure(s, crossing_point(v, w)), s.crossed = true;
      }
    }
    std::vector<std::uint8_t> kept(sections.size(), 0);
    std::size_t nearest = sections.size();
    for (std::size_t i = 0; i < sections.size(); ++i) {
      const Section& s = sections[i];
      if (!s.crossed) continue;
      ++result_.sections;
      if (region.shape == CutRegion::Shape::seed) {
        if (nearest == sections.size() || s.nearest < sections[nearest].nearest) nearest = i;
      } else {
        kept[i] = region.keep == CutRegion::Keep::inside ? s.inside == s.points : s.inside > 0;
      }
    }
    if (nearest < sections.size()) kept[nearest] = 1;
    for (std::size_t i = 0; i < sections.size(); ++i) result_.kept_sections += kept[i];
    std::erase_if(sc_.work, [&](std::int32_t fi) {
      const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
      if (!in_section(f)) return false;
      const std::int32_t root = detail::find_root(parent.data(), f[0]);
      return !kept[static_cast<std::size_t>(section_of[static_cast<std::size_t>(root)])];
    });
    return result_.kept_sections > 0;
  }

  // Step 3's vertex on crossed edge (u, w), made once for the faces on both sides.
  std::int32_t cross_vertex(std::int32_t u, std::int32_t w) {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    std::int32_t id = sc_.crossing.find(a, b);
    if (id >= 0) return id;
    const double da = dist(a), db = dist(b);
    const double t = da / (da - db);
    TopologyChange& ch = result_.change;
    id = nv0_ + static_cast<std::int32_t>(ch.new_vertices.size());
    ch.new_vertices.push_back(NewVertex::on_edge(a, b, t));
    sc_.xpos.push_back((1 - t) * mesh_.current.col(a) + t * mesh_.current.col(b));
    sc_.crossing.insert(a, b, id);
    ++result_.crossed_edges;
    return id;
  }
  Eigen::Vector3d pos(std::int32_t v) const {
    return v < nv0_ ? Eigen::Vector3d(mesh_.current.col(v))
                    : sc_.xpos[static_cast<std::size_t>(v - nv0_)];
  }

  // Step 3: one new vertex per crossed edge; every work face becomes pending faces with a
  // side (split faces in pieces, faces touching the plane re-indexed later if a fan around
  // their plane vertices gets a copy). False when the plane only touches the mesh.
  bool split_crossed_faces() {
    const std::size_t work_size = sc_.work.size();
    sc_.crossing.clear();
    sc_.crossing.reserve(2 * work_size);
    result_.change.new_vertices.reserve(2 * work_size);
    sc_.xpos.clear();
    sc_.xpos.reserve(work_size);
    sc_.pending.clear();
    sc_.pending.reserve(3 * work_size);
    sc_.on_plane.clear();  // (vertex on the plane, pending index)
    split_.reserve(work_size);
    std::size_t next_crossed = 0;  // walks `crossed` along with `work` (both increasing)
    for (const std::int32_t fi : sc_.work) {
      const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
      const std::int8_t s[3] = {sc_.side[static_cast<std::size_t>(f[0])],
                                sc_.side[static_cast<std::size_t>(f[1])],
                                sc_.side[static_cast<std::size_t>(f[2])]};
      if (!is_crossed(s)) {
        keep_face(fi, s);
        continue;
      }
      face_pos_ = face_neg_ = true;
      split_.push_back(fi);
      split_face(fi, s, next_crossed);
    }
    return face_pos_ && face_neg_;
  }

  // A face on one side (or in the plane: the side opposite its normal) touching the plane:
  // pending, in case a fan around its plane vertex gets a copy.
  void keep_face(std::int32_t fi, const std::int8_t* s) {
    const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
    std::int8_t fs = s[0] != 0 ? s[0] : (s[1] != 0 ? s[1] : s[2]);
    if (fs == 0) {
      const Eigen::Vector3d a = mesh_.current.col(f[0]);
      const Eigen::Vector3d normal =
          (mesh_.current.col(f[1]) - a).cross(mesh_.current.col(f[2]) - a);
      fs = normal.dot(plane_.normal()) > 0 ? -1 : 1;
    }
    (fs > 0 ? face_pos_ : face_neg_) = true;
    if (s[0] != 0 && s[1] != 0 && s[2] != 0) return;
    const auto idx = static_cast<std::int32_t>(sc_.pending.size());
    sc_.pending.push_back({f, f, fs, fi});
    for (int k = 0; k < 3; ++k)
      if (s[k] == 0) sc_.on_plane.emplace_back(f[k], idx);
  }

  // A crossed face split into triangles: two through a vertex on the plane, else the lone
  // vertex's triangle and its quad along the diagonal step 2 chose.
  void split_face(std::int32_t fi, const std::int8_t* s, std::size_t& next_crossed) {
    const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
    std::vector<Pending>& pending = sc_.pending;
    int zero = -1;
    for (int k = 0; k < 3; ++k)
      if (s[k] == 0) zero = k;
    if (zero >= 0) {
      const std::int32_t v0 = f[zero], v1 = f[(zero + 1) % 3], v2 = f[(zero + 2) % 3];
      const std::int32_t x = cross_vertex(v1, v2);
      const auto idx = static_cast<std::int32_t>(pending.size());
      pending.push_back({{v0, v1, x}, {v0, v1, x}, s[(zero + 1) % 3], -1});
      pending.push_back({{v0, x, v2}, {v0, x, v2}, s[(zero + 2) % 3], -1});
      sc_.on_plane.emplace_back(v0, idx);
      sc_.on_plane.emplace_back(v0, idx + 1);
      return;
    }
    int lone = 0;
    for (int k = 0; k < 3; ++k)
      if (s[(k + 1) % 3] == s[(k + 2) % 3]) lone = k;
    const std::int32_t v0 = f[lone], v1 = f[(lone + 1) % 3], v2 = f[(lone + 2) % 3];
    const std::int32_t x01 = cross_vertex(v0, v1), x20 = cross_vertex(v2, v0);
    const std::int8_t s0 = s[lone];
    const auto s1 = static_cast<std::int8_t>(-s0);
    pending.push_back({{v0, x01, x20}, {v0, x01, x20}, s0, -1});
    // The diagonal step 2 chose for this face (its last evaluation saw these sides).
    while (sc_.crossed[next_crossed] != fi) ++next_crossed;
    if (sc_.diagonal[next_crossed]) {
      pending.push_back({{x01, v1, v2}, {x01, v1, v2}, s1, -1});
      pending.push_back({{x01, v2, x20}, {x01, v2, x20}, s1, -1});
    } else {
      pending.push_back({{x01, v1, x20}, {x01, v1, x20}, s1, -1});
      pending.push_back({{v1, v2, x20}, {v1, v2, x20}, s1, -1});
    }
  }

  const Pending& pending_at(std::size_t on_plane_index) const {
    return sc_.pending[static_cast<std::size_t>(sc_.on_plane[on_plane_index].second)];
  }

  // Step 4 at the vertices on the plane: faces on one side sharing an edge through the vertex
  // form a fan; the first positive fan keeps the vertex, every other fan gets a copy.
  void separate_fans() {
    auto& on_plane = sc_.on_plane;
    std::sort(on_plane.begin(), on_plane.end());
    for (std::size_t i = 0; i < on_plane.size();) {
      std::size_t j = i;
      while (j < on_plane.size() && on_plane[j].first == on_plane[i].first) ++j;
      separate_fans_at(i, j);
      i = j;
    }
  }

  // The fans of the vertex of on_plane[i, j).
  void separate_fans_at(std::size_t i, std::size_t j) {
    const std::int32_t v = sc_.on_plane[i].first;
    const auto m = static_cast<std::int32_t>(j - i);
    std::vector<std::int32_t>& parent = sc_.parent;
    parent.resize(static_cast<std::size_t>(m));
    std::iota(parent.begin(), parent.end(), 0);
    std::int32_t* const par = parent.data();
    for (std::int32_t a = 0; a < m; ++a)
      for (std::int32_t b = a + 1; b < m; ++b) {
        const Pending& pa = pending_at(i + static_cast<std::size_t>(a));
        const Pending& pb = pending_at(i + static_cast<std::size_t>(b));
        if (pa.side != pb.side) continue;
        bool shared = false;
        for (auto x : pa.pre)
          if (x != v && (x == pb.pre[0] || x == pb.pre[1] || x == pb.pre[2])) shared = true;
        if (shared) detail::unite(par, a, b);
      }
    std::int32_t keeper = -1;
    for (std::int32_t a = 0; a < m && keeper < 0; ++a)
      if (pending_at(i + static_cast<std::size_t>(a)).side > 0) keeper = detail::find_root(par, a);
    if (keeper < 0) keeper = detail::find_root(par, 0);
    TopologyChange& ch = result_.change;
    std::vector<std::pair<std::int32_t, std::int32_t>> copies;  // (fan root, copy id)
    for (std::int32_t a = 0; a < m; ++a) {
      const std::int32_t r = detail::find_root(par, a);
      if (r == keeper) continue;
      std::int32_t id = -1;
      for (const auto& c : copies)
        if (c.first == r) id = c.second;
      if (id < 0) {
        id = nv0_ + static_cast<std::int32_t>(ch.new_vertices.size());
        ch.new_vertices.push_back(NewVertex::duplicate(v));
        copies.emplace_back(r, id);
      }
      Pending& p = sc_.pending[static_cast<std::size_t>(
          sc_.on_plane[i + static_cast<std::size_t>(a)].second)];
      for (auto& x : p.v)
        if (x == v) x = id;
      p.remapped = true;
    }
  }

  // Step 4 at the crossing vertices: the negative side uses a copy.
  void separate_crossings() {
    TopologyChange& ch = result_.change;
    nx_ = static_cast<std::int32_t>(sc_.xpos.size());
    std::vector<std::int32_t>& xcopy = sc_.xcopy;
    xcopy.resize(static_cast<std::size_t>(nx_));
    for (std::int32_t k = 0; k < nx_; ++k) {
      xcopy[static_cast<std::size_t>(k)] = nv0_ + static_cast<std::int32_t>(ch.new_vertices.size());
      ch.new_vertices.push_back(NewVertex::duplicate(nv0_ + k));
    }
    for (Pending& p : sc_.pending)
      if (p.side < 0)
        for (auto& x : p.v)
          if (x >= nv0_ && x < nv0_ + nx_) x = xcopy[static_cast<std::size_t>(x - nv0_)];
  }

  // The change's faces: the pieces of split faces and the re-indexed faces in, their
  // originals out.
  void emit_faces() {
    TopologyChange& ch = result_.change;
    for (const Pending& p : sc_.pending) {
      if (p.original >= 0) {
        if (!p.remapped) continue;
        split_.push_back(p.original);
      }
      ch.added_faces.push_back(p.v);
      result_.added_side.push_back(p.side);
    }
    std::sort(split_.begin(), split_.end());
    ch.removed_faces = std::move(split_);
  }

  // Step 5: caps. Every closed, unambiguous loop goes into one triangulation of the section,
  // in the plane's frame, so that loops inside loops make holes and islands.
  void cap() {
    index_loop_vertices();
    chain_boundary();
    std::vector<std::string> problems;
    std::vector<std::vector<Eigen::Vector2d>> loops2 = closed_loops(problems);
    if (!loops2.empty()) add_cap_faces(loops2, forbidden_diagonals(), problems);
    if (!problems.empty()) result_.message = "not capped: " + problems.front();
  }

  // A loop vertex where the surface meets the plane in several fans: when it is an original
  // vertex that step 2 snapped (not on the plane by itself), compute_cut tries again without
  // snapping it.
  void note_pinch(std::int32_t l) {
    if (l < nx_) return;
    const std::int32_t v = global(l);
    if (std::abs(sc_.dist[static_cast<std::size_t>(v)]) > eps_) pinched_snaps_.push_back(v);
  }

 public:
  const std::vector<std::int32_t>& pinched_snaps() const { return pinched_snaps_; }

 private:
  // Loop vertices (crossing vertices, and original vertices on the plane) get compact local
  // ids — crossing vertex nv0 + k is k, the i-th vertex of `plane_vertices` is nx + i — so
  // that the loop bookkeeping is flat arrays rather than hash maps.
  std::int32_t local(std::int32_t v) const {  // −1 when v is not a loop vertex
    if (v >= nv0_) return v < nv0_ + nx_ ? v - nv0_ : -1;
    if (sc_.side[static_cast<std::size_t>(v)] != 0) return -1;
    const auto& pv = sc_.plane_vertices;
    return nx_ + static_cast<std::int32_t>(std::lower_bound(pv.begin(), pv.end(), v) - pv.begin());
  }
  std::int32_t global(std::int32_t l) const {
    return l < nx_ ? nv0_ + l : sc_.plane_vertices[static_cast<std::size_t>(l - nx_)];
  }

  // The local ids of the pending faces' vertices, and the id each side uses for a loop vertex
  // (conflicting entries make a loop ambiguous).
  void index_loop_vertices() {
    std::vector<std::int32_t>& plane_vertices = sc_.plane_vertices;
    plane_vertices.clear();
    plane_vertices.reserve(sc_.on_plane.size());
    for (const auto& [v, unused] : sc_.on_plane)
      if (plane_vertices.empty() || plane_vertices.back() != v) plane_vertices.push_back(v);
    nloop_ = static_cast<std::size_t>(nx_) + plane_vertices.size();
    const std::vector<Pending>& pending = sc_.pending;
    auto& pending_local = sc_.pending_local;
    pending_local.resize(pending.size());
    for (std::size_t i = 0; i < pending.size(); ++i)
      for (int k = 0; k < 3; ++k) pending_local[i][k] = local(pending[i].pre[k]);
    sc_.copy_plus.assign(nloop_, -1), sc_.copy_minus.assign(nloop_, -1);
    sc_.ambiguous.assign(nloop_, 0);
    for (std::size_t i = 0; i < pending.size(); ++i)
      for (int k = 0; k < 3; ++k) {
        const std::int32_t l = pending_local[i][k];
        if (l < 0) continue;
        std::int32_t& id =
            (pending[i].side > 0 ? sc_.copy_plus : sc_.copy_minus)[static_cast<std::size_t>(l)];
        if (id < 0)
          id = pending[i].v[k];
        else if (id != pending[i].v[k])
          sc_.ambiguous[static_cast<std::size_t>(l)] = 1;
      }
  }

  // The boundary of the positive side created by the cut: directed edges of positive faces
  // between loop vertices whose reverse no positive face has, as next[u] (and their starts).
  void chain_boundary() {
    auto edge_key = [](std::int32_t u, std::int32_t w) {
      return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(w);
    };
    std::vector<std::uint64_t>& plus_edges = sc_.plus_edges;
    plus_edges.clear();
    plus_edges.reserve(sc_.pending.size());
    for (std::size_t i = 0; i < sc_.pending.size(); ++i)
      if (sc_.pending[i].side > 0)
        for (int k = 0; k < 3; ++k) {
          const std::int32_t u = sc_.pending_local[i][k], w = sc_.pending_local[i][(k + 1) % 3];
          if (u >= 0 && w >= 0) plus_edges.push_back(edge_key(u, w));
        }
    std::sort(plus_edges.begin(), plus_edges.end());
    sc_.next.assign(nloop_, -1);
    sc_.starts.clear();
    for (const std::uint64_t e : plus_edges) {
      const auto u = static_cast<std::int32_t>(e >> 32),
                 w = static_cast<std::int32_t>(e & 0xffffffffu);
      if (std::binary_search(plus_edges.begin(), plus_edges.end(), edge_key(w, u))) continue;
      std::int32_t& to = sc_.next[static_cast<std::size_t>(u)];
      if (to >= 0) {
        branching_ = true;
        note_pinch(u);
      } else {
        to = w;
      }
      sc_.starts.push_back(u);
    }
  }

  // Edges of the mesh in the plane whose faces are on one side (a crease of that side touching
  // the plane): they join two loop vertices through the section, and a cap triangle on one
  // would be a third face of that edge. As indices into sc_.ids, for the triangulation to avoid.
  ForbiddenDiagonals forbidden_diagonals() const {
    auto edge_key = [](std::int32_t u, std::int32_t w) {
      return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(w);
    };
    std::vector<std::int32_t> at(nloop_, -1);  // local id → index in sc_.ids
    for (std::size_t i = 0; i < sc_.ids.size(); ++i)
      at[static_cast<std::size_t>(sc_.ids[i])] = static_cast<std::int32_t>(i);
    ForbiddenDiagonals out;
    for (const int side : {1, -1}) {
      std::vector<std::uint64_t> edges;
      for (std::size_t i = 0; i < sc_.pending.size(); ++i)
        if (sc_.pending[i].side == side)
          for (int k = 0; k < 3; ++k) {
            const std::int32_t u = sc_.pending_local[i][k], w = sc_.pending_local[i][(k + 1) % 3];
            if (u >= 0 && w >= 0) edges.push_back(edge_key(u, w));
          }
      std::sort(edges.begin(), edges.end());
      for (const std::uint64_t e : edges) {
        const auto u = static_cast<std::int32_t>(e >> 32),
                   w = static_cast<std::int32_t>(e & 0xffffffffu);
        const std::int32_t a = at[static_cast<std::size_t>(u)], b = at[static_cast<std::size_t>(w)];
        if (u < w && a >= 0 && b >= 0 &&
            std::binary_search(edges.begin(), edges.end(), edge_key(w, u)))
          out.push_back({a, b});
      }
    }
    return out;
  }

  // The closed, unambiguous loops, projected on the plane's frame (e1, e2, n); their local
  // ids concatenated in sc_.ids.
  std::vector<std::vector<Eigen::Vector2d>> closed_loops(std::vector<std::string>& problems) {
    std::vector<std::uint8_t>& visited = sc_.visited;
    visited.assign(nloop_, 0);
    const Eigen::Vector3d n = plane_.normal();
    const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
    std::vector<std::vector<Eigen::Vector2d>> loops2;
    sc_.ids.clear();
    std::vector<std::int32_t>& loop = sc_.loop;
    for (auto s0 : sc_.starts) {
      if (visited[static_cast<std::size_t>(s0)]) continue;
      loop.clear();
      std::int32_t u = s0;
      bool closed = false;
      while (u >= 0 && !visited[static_cast<std::size_t>(u)]) {
        visited[static_cast<std::size_t>(u)] = 1;
        loop.push_back(u);
        u = sc_.next[static_cast<std::size_t>(u)];
        if (u == s0) closed = true;
      }
      if (!closed) {
        problems.push_back("an open cut curve (the surface has a boundary there)");
        continue;
      }
      ++result_.loops;
      bool amb = branching_;
      for (auto v : loop) {
        if (!sc_.ambiguous[static_cast<std::size_t>(v)]) continue;
        amb = true;
        note_pinch(v);
      }
      if (amb) {
        problems.push_back(
            "a cut loop through a vertex where the surface touches the plane in several fans");
        continue;
      }
      auto& p2 = loops2.emplace_back();
      p2.reserve(loop.size());
      for (auto v : loop) {
        const Eigen::Vector3d x = pos(global(v));
        p2.emplace_back(x.dot(e1), x.dot(e2));
      }
      sc_.ids.insert(sc_.ids.end(), loop.begin(), loop.end());
    }
    return loops2;
  }

  // The triangulation of the section (in groups whose loops run as their nesting says,
  // oriented_sections.hpp); each triangle caps both sides. Section triangles turn
  // counter-clockwise about n (clockwise where the surface is inside out): the negative piece's
  // cap faces +n as they are, the positive piece's is reversed.
  void add_cap_faces(const std::vector<std::vector<Eigen::Vector2d>>& loops2,
                     const ForbiddenDiagonals& forbidden, std::vector<std::string>& problems) {
    const detail::OrientedSections section =
        detail::oriented_sections(loops2, options_.cap_triangulator, forbidden);
    if (!section.problem.empty()) {
      problems.push_back(section.problem);
      return;
    }
    result_.capped_loops = section.capped_loops;
    result_.nested_loops = section.nested_loops;
    result_.inside_out_loops = section.inside_out_loops;
    TopologyChange& ch = result_.change;
    ch.added_faces.reserve(ch.added_faces.size() + 2 * section.triangles.size());
    const auto first = static_cast<std::int32_t>(ch.added_faces.size());
    for (const auto& t : section.triangles) {
      Face plus, minus;
      for (int k = 0; k < 3; ++k) {
        const auto v = static_cast<std::size_t>(
            sc_.ids[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])]);
        plus[2 - k] = sc_.copy_plus[v];
        minus[k] = sc_.copy_minus[v];
      }
      if (plus[0] >= 0 && plus[1] >= 0 && plus[2] >= 0) {
        ch.added_faces.push_back(plus);
        result_.added_side.push_back(1);
      }
      if (minus[0] >= 0 && minus[1] >= 0 && minus[2] >= 0) {
        ch.added_faces.push_back(minus);
        result_.added_side.push_back(-1);
      }
      ++result_.cap_faces;
    }
    const auto count = static_cast<std::int32_t>(ch.added_faces.size()) - first;
    if (count > 0) ch.new_surface.push_back({first, count, FaceKind::cap});
  }

  const SkinnedMesh& mesh_;
  const cga::Plane<double> plane_;  // unit normal
  const CutOptions& options_;
  const Predicates predicates_;
  Scratch& sc_;
  const std::int32_t nv0_, nf0_;
  const double snap_, floor_sin2_;
  CutResult result_;
  double diagonal_ = 0, reach_pos_ = 0, reach_neg_ = 0, eps_ = 0;
  bool face_pos_ = false, face_neg_ = false;  // a face lies on that side
  bool outside_work_ = false;  // a vertex not flagged near was snapped: its faces are not in work
  std::vector<std::int32_t> split_;          // the crossed faces, then the re-indexed ones: removed
  std::int32_t nx_ = 0;                      // crossing vertices
  std::size_t nloop_ = 0;                    // loop vertices (local ids)
  bool branching_ = false;                   // a loop vertex with two boundary edges out
  std::vector<std::int32_t> pinched_snaps_;  // snapped vertices where a loop meets itself
};

}  // namespace

namespace detail {

CutResult compute_cut(const SkinnedMesh& mesh, const cga::Plane<double>& plane,
                      const CutOptions& options, Predicates predicates) {
  // A vertex near a saddle of the surface, snapped onto the plane, can make the section meet
  // itself there (the surface touches the plane in two fans around it): that loop cannot be
  // capped. Such vertices are kept off the plane and the cut computed again, while that caps
  // more loops; each round bars at least one more vertex for good, so the rounds end.
  std::vector<std::int32_t>& barred = scratch().unsnappable;
  barred.clear();
  CutComputation first(mesh, plane, options, predicates);
  CutResult best = first.run();
  std::vector<std::int32_t> pinched = first.pinched_snaps();
  for (int round = 0; round < 8 && !pinched.empty() && best.capped_loops < best.loops; ++round) {
    const std::size_t before = barred.size();
    barred.insert(barred.end(), pinched.begin(), pinched.end());
    std::sort(barred.begin(), barred.end());
    barred.erase(std::unique(barred.begin(), barred.end()), barred.end());
    if (barred.size() == before) break;
    CutComputation again(mesh, plane, options, predicates);
    CutResult next = again.run();
    if (next.status != CutStatus::Cut || next.capped_loops <= best.capped_loops) break;
    next.unsnapped_vertices = std::int32_t(barred.size());
    best = std::move(next);
    pinched = again.pinched_snaps();
  }
  barred.clear();
  return best;
}

}  // namespace detail

CutResult compute_cut(const SkinnedMesh& mesh, const cga::Plane<double>& plane,
                      const CutOptions& options) {
  return detail::compute_cut(mesh, plane, options, Predicates::Cga);
}

CutOutcome cut(SkinnedMesh& mesh, Adjacency& adjacency, const cga::Plane<double>& plane,
               const CutOptions& options) {
  CutOutcome out;
  out.result = compute_cut(mesh, plane, options);
  if (out.result.status == CutStatus::Cut) apply(mesh, out.result.change, &adjacency);
  out.pieces = label_pieces(mesh);
  return out;
}

}  // namespace conform::mesh
