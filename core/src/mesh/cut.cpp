#include "conform/mesh/cut.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

#include "conform/cga/point.hpp"

namespace conform::mesh {

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

// The quad (a, b, c, d) split along the diagonal (a, c) or (b, d), whichever gives the larger
// smallest angle (the first on a tie), and that angle's sin².
struct QuadSplit {
  bool first_diagonal;
  double quality;
};
QuadSplit best_quad_split(const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                          const Eigen::Vector3d& c, const Eigen::Vector3d& d) {
  const double q1 = std::min(smallest_angle_sin2(a, b, c), smallest_angle_sin2(a, c, d));
  const double q2 = std::min(smallest_angle_sin2(a, b, d), smallest_angle_sin2(b, c, d));
  return q1 >= q2 ? QuadSplit{true, q1} : QuadSplit{false, q2};
}

// compute_cut's working arrays, kept per thread between calls so that a cut at haptic rates
// allocates only what it returns.
struct Scratch {
  std::vector<double> dist;
  std::vector<std::int8_t> side;
  std::vector<std::uint8_t> code;
  std::vector<std::int32_t> work, crossed, evaluate, again, snapped_now, parent, xcopy,
      plane_vertices, copy_plus, copy_minus, next, starts, ids, loop;
  EdgeMap crossing;
  std::vector<Eigen::Vector3d> xpos;
  std::vector<Pending> pending;
  std::vector<std::pair<std::int32_t, std::int32_t>> on_plane;
  std::vector<std::array<std::int32_t, 3>> pending_local;
  std::vector<std::uint8_t> ambiguous, visited, diagonal;
  std::vector<std::uint64_t> plus_edges;
};
Scratch& scratch() {
  thread_local Scratch s;
  return s;
}

std::int32_t root(std::vector<std::int32_t>& p, std::int32_t x) {
  while (p[static_cast<std::size_t>(x)] != x)
    x = p[static_cast<std::size_t>(x)] =
        p[static_cast<std::size_t>(p[static_cast<std::size_t>(x)])];
  return x;
}

}  // namespace

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

CutResult compute_cut(const SkinnedMesh& mesh, const cga::Plane<double>& plane_in,
                      const CutOptions& options) {
  const cga::Plane<double> plane = unit_plane(plane_in);
  if (!(options.snap_fraction >= 0 && options.snap_fraction < 0.5) ||
      !(options.plane_tolerance >= 0) || !(options.min_angle >= 0 && options.min_angle < 0.5))
    throw std::invalid_argument(
        "cut: snap_fraction must be in [0, 0.5), plane_tolerance ≥ 0 and min_angle in [0, 0.5)");
  const std::int32_t nv0 = mesh.vertex_count();
  const std::int32_t nf0 = mesh.face_count();
  if (mesh.current.cols() != nv0)
    throw std::invalid_argument("cut: the current positions must be finite, one per vertex");
  // One pass over the positions: finite, their bounding box (the tolerance's scale), step 1's
  // signed distances (the same predicates as classify_vertices) and the farthest vertex on
  // each side.
  Scratch& sc = scratch();
  std::vector<double>& dist = sc.dist;
  dist.resize(static_cast<std::size_t>(nv0));
  double diagonal = 0, reach_pos = 0, reach_neg = 0;
  if (nv0 > 0) {
    const double* x = mesh.current.data();
    double lo[3] = {x[0], x[1], x[2]}, hi[3] = {x[0], x[1], x[2]};
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
    if (options.predicates == Predicates::Cga) {
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
    diagonal = std::sqrt((hi[0] - lo[0]) * (hi[0] - lo[0]) + (hi[1] - lo[1]) * (hi[1] - lo[1]) +
                         (hi[2] - lo[2]) * (hi[2] - lo[2]));
  }
  CutResult result;
  result.change.base_vertex_count = nv0;
  result.change.base_face_count = nf0;
  if (nf0 == 0) return result;

  const double eps = options.plane_tolerance * diagonal;
  if (!(reach_pos > eps) || !(reach_neg > eps)) {
    // Every vertex on one side or on the plane: only faces lying in the plane could separate,
    // and they go to the side of the material (opposite their normal), i.e. the same side.
    result.message = "the plane does not cross the mesh";
    return result;
  }
  // Step 2 below snaps a vertex at distance d of the plane only across an edge to a vertex at
  // distance d' on the other side with |d| < snap / (1 − snap) · |d'|, so only vertices nearer
  // than that to the plane, measured with the other side's reach, can be snapped: "near".
  // Per vertex code: 1 on the plane, 2 positive, 8 negative, + 16 when near.
  const double snap = options.snap_fraction;
  const double k_snap = snap / (1 - snap) * (1 + 1e-9);  // a margin for rounding
  const double near_pos = k_snap * reach_neg, near_neg = k_snap * reach_pos;
  std::vector<std::int8_t>& side = sc.side;
  std::vector<std::uint8_t>& code = sc.code;
  side.resize(static_cast<std::size_t>(nv0));
  code.resize(static_cast<std::size_t>(nv0));
  for (std::int32_t i = 0; i < nv0; ++i) {
    const double s = dist[static_cast<std::size_t>(i)];
    const std::int8_t si = s > eps ? 1 : (s < -eps ? -1 : 0);
    side[static_cast<std::size_t>(i)] = si;
    code[static_cast<std::size_t>(i)] =
        static_cast<std::uint8_t>((si == 0  ? 1
                                   : si > 0 ? 2
                                            : 8) |
                                  ((si > 0 && s < near_pos) || (si < 0 && -s < near_neg) ? 16 : 0));
  }
  // One pass over the faces: index check, and the faces that need work — crossed, touching
  // the plane, or with a near vertex (which snapping may put on the plane) — in increasing
  // order. The rest only tell which sides have faces.
  const auto nf = static_cast<std::size_t>(nf0);
  const Face* const faces = mesh.faces.data();
  std::int8_t* const sd = side.data();
  const std::uint8_t* const cd = code.data();
  std::vector<std::int32_t>& work = sc.work;
  work.clear();
  work.reserve(256);
  bool face_pos = false, face_neg = false;
  {
    int any = 0;
    const auto bound = static_cast<std::uint32_t>(nv0);
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
    face_pos = (any & 2) != 0, face_neg = (any & 8) != 0;
  }

  // Step 2, snapping, face by face: a crossed face whose split (by the vertices' current sides)
  // would make a triangle with smallest angle below its bound — min(min_angle, half the
  // face's smallest angle) — or whose crossing lies within snap_fraction of an edge's end, has
  // one vertex taken as on the plane: of the vertices whose snapping makes this face acceptable
  // (the lone vertex always does), the nearest to the plane. Snapping only uncrosses faces, so
  // the faces a snap touched are evaluated again until none snaps. Vertices never move.
  const double* const px = mesh.current.data();
  auto point = [px](std::int32_t v) { return Eigen::Vector3d::Map(px + 3 * std::size_t(v)); };
  auto crossing_point = [&](std::int32_t u, std::int32_t w) -> Eigen::Vector3d {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    const double da = dist[static_cast<std::size_t>(a)], db = dist[static_cast<std::size_t>(b)];
    const double t = da / (da - db);
    return (1 - t) * point(a) + t * point(b);
  };
  auto crossing_t = [&](std::int32_t from, std::int32_t to) {  // from `from` along the edge
    const double df = dist[static_cast<std::size_t>(from)], dt = dist[static_cast<std::size_t>(to)];
    return df / (df - dt);
  };
  // The split of face f with sides s (crossed): the quality (smallest angle's sin²) of its
  // worst triangle, or −1 when a crossing falls within `snap` of an edge's end; for a lone
  // vertex, `first_diagonal` tells how its quad is split (as step 3 will).
  auto split_quality = [&](const Face& f, const std::int8_t* s, bool* first_diagonal) {
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
    const QuadSplit quad = best_quad_split(x01, p1, p2, x20);
    if (first_diagonal) *first_diagonal = quad.first_diagonal;
    return std::min(smallest_angle_sin2(p0, x01, x20), quad.quality);
  };
  const double floor_sin2 = std::sin(options.min_angle) * std::sin(options.min_angle);
  std::vector<std::int32_t>&crossed = sc.crossed, &evaluate = sc.evaluate, &again = sc.again,
  &snapped_now = sc.snapped_now;
  crossed.clear(), evaluate.clear(), again.clear(), snapped_now.clear();
  std::vector<std::uint8_t>& quad_diagonal = sc.diagonal;  // per crossed face, for step 3
  bool outside_work = false;  // a vertex not flagged near was snapped: its faces are not in work
  for (const std::int32_t fi : work) {
    const Face& f = faces[fi];
    if (sd[f[0]] * sd[f[1]] < 0 || sd[f[1]] * sd[f[2]] < 0 || sd[f[2]] * sd[f[0]] < 0)
      crossed.push_back(fi);
  }
  quad_diagonal.assign(crossed.size(), 1);
  for (std::size_t i = 0; i < crossed.size(); ++i) evaluate.push_back(static_cast<std::int32_t>(i));
  while (!evaluate.empty()) {
    snapped_now.clear();
    for (const std::int32_t ci : evaluate) {
      const Face& f = faces[crossed[static_cast<std::size_t>(ci)]];
      std::int8_t s[3] = {sd[f[0]], sd[f[1]], sd[f[2]]};
      if (!(s[0] * s[1] < 0 || s[1] * s[2] < 0 || s[2] * s[0] < 0)) continue;
      bool first_diagonal = true;
      const double quality = split_quality(f, s, &first_diagonal);
      quad_diagonal[static_cast<std::size_t>(ci)] = first_diagonal;
      if (quality >= floor_sin2) continue;  // the bound is never above the floor
      const double bound =
          sliver_bound_sin2(point(f[0]), point(f[1]), point(f[2]), options.min_angle);
      if (quality >= bound) continue;
      // The fewest vertices, nearest the plane, that make this face acceptable: taking two of
      // its vertices as on the plane always does (it is no longer crossed), so the nearest alone
      // if that suffices, else the second nearest alone if that does, else both.
      int order[3] = {0, 1, 2};
      std::sort(order, order + 3, [&](int i, int j) {
        const double di = s[i] == 0 ? -1 : std::abs(dist[static_cast<std::size_t>(f[i])]);
        const double dj = s[j] == 0 ? -1 : std::abs(dist[static_cast<std::size_t>(f[j])]);
        return di < dj || (di == dj && i < j);
      });
      const int first = s[order[0]] == 0 ? 1 : 0;  // skip a vertex already on the plane
      auto acceptable_without = [&](int k) {
        const std::int8_t keep = s[k];
        s[k] = 0;
        const bool ok = !(s[0] * s[1] < 0 || s[1] * s[2] < 0 || s[2] * s[0] < 0) ||
                        split_quality(f, s, nullptr) >= bound;
        s[k] = keep;
        return ok;
      };
      auto snap_vertex = [&](std::int32_t v) {
        sd[v] = 0;
        ++result.snapped_vertices;
        snapped_now.push_back(v);
        if (!(cd[v] & 16)) outside_work = true;
      };
      if (acceptable_without(order[first])) {
        snap_vertex(f[order[first]]);
      } else if (first == 0 && acceptable_without(order[1])) {
        snap_vertex(f[order[1]]);
      } else {
        snap_vertex(f[order[first]]);
        if (first == 0) snap_vertex(f[order[1]]);
      }
    }
    // Faces touched by this round's snaps that are still crossed: evaluate them again.
    std::sort(snapped_now.begin(), snapped_now.end());
    again.clear();
    if (!snapped_now.empty())
      for (std::size_t ci = 0; ci < crossed.size(); ++ci) {
        const Face& f = faces[crossed[ci]];
        bool touched = false;
        for (auto v : f) touched |= std::binary_search(snapped_now.begin(), snapped_now.end(), v);
        if (touched &&
            (sd[f[0]] * sd[f[1]] < 0 || sd[f[1]] * sd[f[2]] < 0 || sd[f[2]] * sd[f[0]] < 0))
          again.push_back(static_cast<std::int32_t>(ci));
      }
    evaluate.swap(again);
  }
  if (outside_work) {
    // Rare (a crossing far along its edge, in a poorly shaped face): the faces around a snapped
    // vertex that step 1 did not flag, found by one more pass over the faces.
    const auto before = work.size();
    for (std::size_t fi = 0; fi < nf; ++fi) {
      const Face& f = faces[fi];
      const int fc = cd[f[0]] | cd[f[1]] | cd[f[2]];
      if (!(fc == 2 || fc == 8)) continue;  // already in work
      if (sd[f[0]] == 0 || sd[f[1]] == 0 || sd[f[2]] == 0)
        work.push_back(static_cast<std::int32_t>(fi));
    }
    std::inplace_merge(work.begin(), work.begin() + static_cast<std::ptrdiff_t>(before),
                       work.end());
  }

  TopologyChange& ch = result.change;
  EdgeMap& crossing = sc.crossing;  // (lower, higher) vertex → crossing vertex id
  crossing.clear();
  crossing.reserve(2 * work.size());
  ch.new_vertices.reserve(2 * work.size());
  std::vector<Eigen::Vector3d>& xpos = sc.xpos;
  xpos.clear();
  xpos.reserve(work.size());
  auto cross_vertex = [&](std::int32_t u, std::int32_t w) {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    std::int32_t id = crossing.find(a, b);
    if (id >= 0) return id;
    const double da = dist[static_cast<std::size_t>(a)], db = dist[static_cast<std::size_t>(b)];
    const double t = da / (da - db);
    id = nv0 + static_cast<std::int32_t>(ch.new_vertices.size());
    ch.new_vertices.push_back(NewVertex::on_edge(a, b, t));
    xpos.push_back((1 - t) * mesh.current.col(a) + t * mesh.current.col(b));
    crossing.insert(a, b, id);
    ++result.crossed_edges;
    return id;
  };
  auto pos = [&](std::int32_t v) -> Eigen::Vector3d {
    return v < nv0 ? Eigen::Vector3d(mesh.current.col(v)) : xpos[static_cast<std::size_t>(v - nv0)];
  };

  std::vector<Pending>& pending = sc.pending;
  pending.clear();
  pending.reserve(3 * work.size());
  std::vector<std::pair<std::int32_t, std::int32_t>>& on_plane =
      sc.on_plane;  // (vertex on the plane, pending index)
  on_plane.clear();
  std::vector<std::int32_t> split;
  split.reserve(work.size());
  const Eigen::Vector3d n = plane.normal();
  std::size_t next_crossed = 0;  // walks `crossed` along with `work` (both increasing)
  for (const std::int32_t fi : work) {
    const Face& f = faces[fi];
    const std::int8_t s[3] = {side[static_cast<std::size_t>(f[0])],
                              side[static_cast<std::size_t>(f[1])],
                              side[static_cast<std::size_t>(f[2])]};
    const bool crossed = s[0] * s[1] < 0 || s[1] * s[2] < 0 || s[2] * s[0] < 0;
    if (!crossed) {
      std::int8_t fs = s[0] != 0 ? s[0] : (s[1] != 0 ? s[1] : s[2]);
      if (fs == 0) {
        const Eigen::Vector3d a = mesh.current.col(f[0]);
        const Eigen::Vector3d normal =
            (mesh.current.col(f[1]) - a).cross(mesh.current.col(f[2]) - a);
        fs = normal.dot(n) > 0 ? -1 : 1;
      }
      (fs > 0 ? face_pos : face_neg) = true;
      if (s[0] != 0 && s[1] != 0 && s[2] != 0) continue;
      const auto idx = static_cast<std::int32_t>(pending.size());
      pending.push_back({f, f, fs, fi});
      for (int k = 0; k < 3; ++k)
        if (s[k] == 0) on_plane.emplace_back(f[k], idx);
      continue;
    }
    face_pos = face_neg = true;
    split.push_back(fi);
    int zero = -1;
    for (int k = 0; k < 3; ++k)
      if (s[k] == 0) zero = k;
    if (zero >= 0) {
      const std::int32_t v0 = f[zero], v1 = f[(zero + 1) % 3], v2 = f[(zero + 2) % 3];
      const std::int32_t x = cross_vertex(v1, v2);
      const auto idx = static_cast<std::int32_t>(pending.size());
      pending.push_back({{v0, v1, x}, {v0, v1, x}, s[(zero + 1) % 3], -1});
      pending.push_back({{v0, x, v2}, {v0, x, v2}, s[(zero + 2) % 3], -1});
      on_plane.emplace_back(v0, idx);
      on_plane.emplace_back(v0, idx + 1);
      continue;
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
    while (sc.crossed[next_crossed] != fi) ++next_crossed;
    if (quad_diagonal[next_crossed]) {
      pending.push_back({{x01, v1, v2}, {x01, v1, v2}, s1, -1});
      pending.push_back({{x01, v2, x20}, {x01, v2, x20}, s1, -1});
    } else {
      pending.push_back({{x01, v1, x20}, {x01, v1, x20}, s1, -1});
      pending.push_back({{v1, v2, x20}, {v1, v2, x20}, s1, -1});
    }
  }
  if (!face_pos || !face_neg) {
    ch.new_vertices.clear();
    result.crossed_edges = 0;
    result.message = "the plane only touches the mesh";
    return result;
  }

  // Separate the fans around vertices on the plane: faces on one side sharing an edge through
  // the vertex form a fan; the first positive fan keeps the vertex, every other fan gets a copy.
  std::sort(on_plane.begin(), on_plane.end());
  std::vector<std::int32_t>& parent = sc.parent;
  for (std::size_t i = 0; i < on_plane.size();) {
    std::size_t j = i;
    while (j < on_plane.size() && on_plane[j].first == on_plane[i].first) ++j;
    const std::int32_t v = on_plane[i].first;
    const auto m = static_cast<std::int32_t>(j - i);
    parent.resize(static_cast<std::size_t>(m));
    std::iota(parent.begin(), parent.end(), 0);
    for (std::int32_t a = 0; a < m; ++a)
      for (std::int32_t b = a + 1; b < m; ++b) {
        const Pending& pa =
            pending[static_cast<std::size_t>(on_plane[i + static_cast<std::size_t>(a)].second)];
        const Pending& pb =
            pending[static_cast<std::size_t>(on_plane[i + static_cast<std::size_t>(b)].second)];
        if (pa.side != pb.side) continue;
        bool shared = false;
        for (auto x : pa.pre)
          if (x != v && (x == pb.pre[0] || x == pb.pre[1] || x == pb.pre[2])) shared = true;
        if (shared) parent[static_cast<std::size_t>(root(parent, a))] = root(parent, b);
      }
    std::int32_t keeper = -1;
    for (std::int32_t a = 0; a < m && keeper < 0; ++a)
      if (pending[static_cast<std::size_t>(on_plane[i + static_cast<std::size_t>(a)].second)].side >
          0)
        keeper = root(parent, a);
    if (keeper < 0) keeper = root(parent, 0);
    std::vector<std::pair<std::int32_t, std::int32_t>> copies;  // (fan root, copy id)
    for (std::int32_t a = 0; a < m; ++a) {
      const std::int32_t r = root(parent, a);
      if (r == keeper) continue;
      std::int32_t id = -1;
      for (const auto& c : copies)
        if (c.first == r) id = c.second;
      if (id < 0) {
        id = nv0 + static_cast<std::int32_t>(ch.new_vertices.size());
        ch.new_vertices.push_back(NewVertex::duplicate(v));
        copies.emplace_back(r, id);
      }
      Pending& p =
          pending[static_cast<std::size_t>(on_plane[i + static_cast<std::size_t>(a)].second)];
      for (auto& x : p.v)
        if (x == v) x = id;
      p.remapped = true;
    }
    i = j;
  }
  // Crossing vertices: the negative side uses a copy.
  const auto nx = static_cast<std::int32_t>(xpos.size());
  std::vector<std::int32_t>& xcopy = sc.xcopy;
  xcopy.resize(static_cast<std::size_t>(nx));
  for (std::int32_t k = 0; k < nx; ++k) {
    xcopy[static_cast<std::size_t>(k)] = nv0 + static_cast<std::int32_t>(ch.new_vertices.size());
    ch.new_vertices.push_back(NewVertex::duplicate(nv0 + k));
  }
  for (Pending& p : pending)
    if (p.side < 0)
      for (auto& x : p.v)
        if (x >= nv0 && x < nv0 + nx) x = xcopy[static_cast<std::size_t>(x - nv0)];

  for (const Pending& p : pending) {
    if (p.original >= 0) {
      if (!p.remapped) continue;
      split.push_back(p.original);
    }
    ch.added_faces.push_back(p.v);
    result.added_side.push_back(p.side);
  }
  std::sort(split.begin(), split.end());
  ch.removed_faces = std::move(split);
  result.status = CutStatus::Cut;

  if (!options.cap) return result;

  // Caps. Loop vertices (crossing vertices, and original vertices on the plane) get compact
  // local ids — crossing vertex nv0 + k is k, the i-th vertex of `plane_vertices` is nx + i —
  // so that the loop bookkeeping is flat arrays rather than hash maps.
  std::vector<std::int32_t>& plane_vertices = sc.plane_vertices;
  plane_vertices.clear();
  plane_vertices.reserve(on_plane.size());
  for (const auto& [v, unused] : on_plane)
    if (plane_vertices.empty() || plane_vertices.back() != v) plane_vertices.push_back(v);
  const auto nloop = static_cast<std::size_t>(nx) + plane_vertices.size();
  auto local = [&](std::int32_t v) -> std::int32_t {  // −1 when v is not a loop vertex
    if (v >= nv0) return v < nv0 + nx ? v - nv0 : -1;
    if (side[static_cast<std::size_t>(v)] != 0) return -1;
    return nx + static_cast<std::int32_t>(
                    std::lower_bound(plane_vertices.begin(), plane_vertices.end(), v) -
                    plane_vertices.begin());
  };
  auto global = [&](std::int32_t l) {
    return l < nx ? nv0 + l : plane_vertices[static_cast<std::size_t>(l - nx)];
  };
  // Per pending face, its vertices' local ids (−1 for others).
  std::vector<std::array<std::int32_t, 3>>& pending_local = sc.pending_local;
  pending_local.resize(pending.size());
  for (std::size_t i = 0; i < pending.size(); ++i)
    for (int k = 0; k < 3; ++k) pending_local[i][k] = local(pending[i].pre[k]);
  // The id each side uses for a loop vertex; conflicting entries make a loop ambiguous.
  std::vector<std::int32_t>&copy_plus = sc.copy_plus, &copy_minus = sc.copy_minus;
  copy_plus.assign(nloop, -1), copy_minus.assign(nloop, -1);
  std::vector<std::uint8_t>& ambiguous = sc.ambiguous;
  ambiguous.assign(nloop, 0);
  for (std::size_t i = 0; i < pending.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const std::int32_t l = pending_local[i][k];
      if (l < 0) continue;
      std::int32_t& id =
          (pending[i].side > 0 ? copy_plus : copy_minus)[static_cast<std::size_t>(l)];
      if (id < 0)
        id = pending[i].v[k];
      else if (id != pending[i].v[k])
        ambiguous[static_cast<std::size_t>(l)] = 1;
    }
  // The boundary of the positive side created by the cut: directed edges of positive faces
  // between loop vertices whose reverse no positive face has.
  auto edge_key = [](std::int32_t u, std::int32_t w) {
    return (std::uint64_t(std::uint32_t(u)) << 32) | std::uint32_t(w);
  };
  std::vector<std::uint64_t>& plus_edges = sc.plus_edges;
  plus_edges.clear();
  plus_edges.reserve(pending.size());
  for (std::size_t i = 0; i < pending.size(); ++i)
    if (pending[i].side > 0)
      for (int k = 0; k < 3; ++k) {
        const std::int32_t u = pending_local[i][k], w = pending_local[i][(k + 1) % 3];
        if (u >= 0 && w >= 0) plus_edges.push_back(edge_key(u, w));
      }
  std::sort(plus_edges.begin(), plus_edges.end());
  std::vector<std::int32_t>& next = sc.next;  // boundary edge u → next[u]
  next.assign(nloop, -1);
  std::vector<std::int32_t>& starts = sc.starts;
  starts.clear();
  bool branching = false;
  for (const std::uint64_t e : plus_edges) {
    const auto u = static_cast<std::int32_t>(e >> 32),
               w = static_cast<std::int32_t>(e & 0xffffffffu);
    if (std::binary_search(plus_edges.begin(), plus_edges.end(), edge_key(w, u))) continue;
    std::int32_t& to = next[static_cast<std::size_t>(u)];
    if (to >= 0)
      branching = true;
    else
      to = w;
    starts.push_back(u);
  }
  std::vector<std::uint8_t>& visited = sc.visited;
  visited.assign(nloop, 0);
  std::vector<std::string> problems;
  // Every closed, unambiguous loop goes into one triangulation of the section, in the plane's
  // frame (e1, e2, n), so that loops inside loops make holes and islands.
  const Eigen::Vector3d e1 = n.unitOrthogonal(), e2 = n.cross(e1);
  std::vector<std::int32_t>& ids =
      sc.ids;  // the section's vertices (local ids), loops concatenated
  std::vector<std::vector<Eigen::Vector2d>> loops2;
  ids.clear();
  std::vector<std::int32_t>& loop = sc.loop;
  for (auto s0 : starts) {
    if (visited[static_cast<std::size_t>(s0)]) continue;
    loop.clear();
    std::int32_t u = s0;
    bool closed = false;
    while (u >= 0 && !visited[static_cast<std::size_t>(u)]) {
      visited[static_cast<std::size_t>(u)] = 1;
      loop.push_back(u);
      u = next[static_cast<std::size_t>(u)];
      if (u == s0) closed = true;
    }
    if (!closed) {
      problems.push_back("an open cut curve (the surface has a boundary there)");
      continue;
    }
    ++result.loops;
    bool amb = branching;
    for (auto v : loop) amb |= ambiguous[static_cast<std::size_t>(v)] != 0;
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
    ids.insert(ids.end(), loop.begin(), loop.end());
  }
  if (!loops2.empty()) {
    const SectionTriangulation section = triangulate_section(loops2, options.cap_triangulator);
    if (!section.ok()) {
      problems.push_back(section.problem);
    } else {
      result.capped_loops = static_cast<std::int32_t>(loops2.size());
      for (auto d : section.depth) result.nested_loops += d > 0;
      // Section triangles turn counter-clockwise about n: the negative piece's cap faces +n
      // as they are, the positive piece's is reversed.
      ch.added_faces.reserve(ch.added_faces.size() + 2 * section.triangles.size());
      for (const auto& t : section.triangles) {
        Face plus, minus;
        for (int k = 0; k < 3; ++k) {
          const auto v = static_cast<std::size_t>(
              ids[static_cast<std::size_t>(t[static_cast<std::size_t>(k)])]);
          plus[2 - k] = copy_plus[v];
          minus[k] = copy_minus[v];
        }
        if (plus[0] >= 0 && plus[1] >= 0 && plus[2] >= 0) {
          ch.added_faces.push_back(plus);
          result.added_side.push_back(1);
        }
        if (minus[0] >= 0 && minus[1] >= 0 && minus[2] >= 0) {
          ch.added_faces.push_back(minus);
          result.added_side.push_back(-1);
        }
        ++result.cap_faces;
      }
    }
  }
  if (!problems.empty()) result.message = "not capped: " + problems.front();
  return result;
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
