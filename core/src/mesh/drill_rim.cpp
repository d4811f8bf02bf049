#include "drill_rim.hpp"

#include <cmath>

namespace conform::mesh::drilling {

namespace {

// No slivers: every face the drill adds keeps its smallest angle at least
// min(min_angle, half the smallest angle of the original face it lies in). Rivara's
// bisection keeps half; a face the rim clips is cut into pieces (clip_faces in drill.cpp) whose
// angles depend on where the rim crosses its edges: while a piece would be sharper than the
// bound, one more vertex of that face is taken as a rim vertex (snapped): the nearest to its
// crossing point of those whose snap leaves the face's pieces within the bound and whose
// crossing point is within kAngleSnap of the crossed edge from it. A snap changes the pieces of
// the faces around the vertex, hence the passes; every pass snaps at least one vertex for good,
// so they end. A face that no such snap mends is bisected (Rivara) and the classification
// starts again (at most kMendRounds times); in the last round the nearest vertex that mends
// the face is snapped however far (else the nearest), so that the bound holds.
constexpr double kAngleSnap = 0.1;
constexpr int kMendRounds = 4;

class RimClassifier {
 public:
  RimClassifier(Region& region, const std::vector<Patch>& patches, const SkinnedMesh& mesh,
                const Axis& axis, const DrillOptions& options, DrillResult& result)
      : region_(region),
        patches_(patches),
        mesh_(mesh),
        axis_(axis),
        options_(options),
        result_(result),
        angle_floor_(std::max(options.min_angle, 0.0)),
        max_depth_(2 * std::max(options.max_refinements, 0)) {}

  void run() {
    auto& unmended = region_.work;
    for (int round = 0;; ++round) {
      const bool last = round == kMendRounds;
      if (round > 0) {  // after bisections: classify afresh
        for (auto& v : region_.verts) v.side = region_.inside(v.q) ? -1 : 1;
        result_.snapped_rim_vertices = 0;
      }
      snap_near();
      unmended.clear();
      mend_by_snapping(round, last, unmended);
      if (last) break;
      std::vector<std::int32_t> mend = faces_to_bisect(unmended);
      if (mend.empty()) break;
      std::sort(mend.begin(), mend.end());
      mend.erase(std::unique(mend.begin(), mend.end()), mend.end());
      for (auto f : mend) region_.refine(f);
    }
    int depth = 0;
    for (const auto& lf : region_.faces) depth = std::max(depth, int(lf.depth));
    result_.refinements = (depth + 1) / 2;
  }

 private:
  double crossing_t(std::int32_t a, std::int32_t b) const {
    return rim_crossing_t(region_, axis_, a, b);
  }
  Eigen::Vector3d crossing_x(std::int32_t u, std::int32_t w) const {
    const std::int32_t a = std::min(u, w), b = std::max(u, w);
    const double t = crossing_t(a, b);
    return (1 - t) * region_.verts[std::size_t(a)].x + t * region_.verts[std::size_t(b)].x;
  }

  // A vertex closer to the rim than snap_fraction of an edge it ends is taken as a rim vertex.
  void snap_near() {
    for (std::size_t f = 0; f < region_.faces.size(); ++f)
      for (int k = 0; k < 3; ++k) {
        const Region::LocalFace& lf = region_.faces[f];
        if (lf.twin[k] >= 0 && lf.twin[k] < std::int32_t(3 * f) + k) continue;  // each edge once
        const std::int32_t a = std::min(lf.v[k], lf.v[(k + 1) % 3]),
                           b = std::max(lf.v[k], lf.v[(k + 1) % 3]);
        auto &va = region_.verts[std::size_t(a)], &vb = region_.verts[std::size_t(b)];
        if (va.side * vb.side >= 0) continue;
        const double t = crossing_t(a, b);
        if (t < options_.snap_fraction)
          va.side = 0, ++result_.snapped_rim_vertices;
        else if (t > 1 - options_.snap_fraction)
          vb.side = 0, ++result_.snapped_rim_vertices;
      }
  }

  // The smallest angle of the pieces of local face t that stay (as clip_faces emits them), as
  // its tangent (smallest_angle); +∞ when the rim does not clip it.
  double pieces_angle(const std::array<std::int32_t, 3>& t) const {
    const auto& X = region_.verts;
    const int s[3] = {X[std::size_t(t[0])].side, X[std::size_t(t[1])].side,
                      X[std::size_t(t[2])].side};
    const bool in = s[0] < 0 || s[1] < 0 || s[2]<0, out = s[0]> 0 || s[1] > 0 || s[2] > 0;
    if (!in || !out) return std::numeric_limits<double>::infinity();
    for (int k = 0; k < 3; ++k)
      if (s[k] == 0) {
        // The piece between the rim vertex, the outside vertex and the crossing.
        const std::int32_t v0 = t[k], v1 = t[(k + 1) % 3], v2 = t[(k + 2) % 3];
        const std::int32_t outside = X[std::size_t(v1)].side > 0 ? v1 : v2;
        return smallest_angle(X[std::size_t(v0)].x, X[std::size_t(outside)].x, crossing_x(v1, v2));
      }
    int lone = 0;
    for (int k = 0; k < 3; ++k)
      if (s[(k + 1) % 3] == s[(k + 2) % 3]) lone = k;
    const std::int32_t v0 = t[lone], v1 = t[(lone + 1) % 3], v2 = t[(lone + 2) % 3];
    const Eigen::Vector3d x01 = crossing_x(v0, v1), x20 = crossing_x(v2, v0);
    const Eigen::Vector3d &p0 = X[std::size_t(v0)].x, &p1 = X[std::size_t(v1)].x,
                          &p2 = X[std::size_t(v2)].x;
    if (s[lone] > 0) return smallest_angle(p0, x01, x20);
    // The quad (x01, v1, v2, x20), split as clip_faces will.
    return drill_quad_split(x01, p1, p2, x20).quality;
  }

  // The angle guarantee's bound of a local face (as a tangent), from its original face.
  double bound(const Region::LocalFace& lf) {
    auto& o = region_.origins[std::size_t(lf.origin)];
    if (o.bound < 0) {
      const Face& t = mesh_.faces[std::size_t(o.face)];
      const double original = std::atan(smallest_angle(
          mesh_.current.col(t[0]), mesh_.current.col(t[1]), mesh_.current.col(t[2])));
      o.bound = std::tan(std::min(angle_floor_, 0.5 * original));  // as a tangent
    }
    return o.bound;
  }

  // The passes of one round: snap, face by face, one vertex that mends a clipped face's pieces;
  // faces that no snap mends go to `unmended`. Only clipped faces make pieces, and a snap never
  // clips a face that was not: after the first pass, only the clipped faces with a vertex
  // snapped in the pass before are seen.
  void mend_by_snapping(int round, bool last, std::vector<std::int32_t>& unmended) {
    auto& clipped = region_.clipped;
    clipped.clear();
    if (angle_floor_ > 0)
      for (std::size_t f = 0; f < region_.faces.size(); ++f) {
        bool in = false, out = false;
        for (auto v : region_.faces[f].v) {
          in = in || region_.verts[std::size_t(v)].side < 0;
          out = out || region_.verts[std::size_t(v)].side > 0;
        }
        if (in && out) clipped.push_back(std::int32_t(f));
      }
    for (int pass = 0; pass < 64; ++pass) {
      bool snapped = false;
      const int stamp = 64 * round + pass;
      for (const std::int32_t f : clipped) {
        const Region::LocalFace& lf = region_.faces[std::size_t(f)];
        if (pass > 0 && region_.verts[std::size_t(lf.v[0])].snapped != stamp - 1 &&
            region_.verts[std::size_t(lf.v[1])].snapped != stamp - 1 &&
            region_.verts[std::size_t(lf.v[2])].snapped != stamp - 1)
          continue;
        const double b = bound(lf);
        if (pieces_angle(lf.v) >= b) continue;
        const std::int32_t pick = mending_snap(lf, b, last);
        if (pick == kNoCandidate) continue;
        if (pick < 0) {
          unmended.push_back(f);
          continue;
        }
        region_.verts[std::size_t(pick)].side = 0;
        region_.verts[std::size_t(pick)].snapped = stamp;
        ++result_.snapped_rim_vertices;
        snapped = true;
      }
      if (!snapped) break;
    }
  }

  static constexpr std::int32_t kNoCandidate = -2;

  // The vertex of lf to snap: the nearest to its crossing point whose snap mends lf (within
  // kAngleSnap of the crossed edge, unless `last`; then the nearest if none mends); −1 when
  // none does, kNoCandidate when the rim crosses none of lf's edges.
  std::int32_t mending_snap(const Region::LocalFace& lf, double b, bool last) {
    // The candidates: the ends of the edges the rim crosses, by distance to the crossing
    // (and that distance over the edge's length).
    struct Candidate {
      double distance2, fraction;
      std::int32_t v;
    };
    std::array<Candidate, 3> candidates;
    int count = 0;
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = lf.v[k];
      const auto& x = region_.verts[std::size_t(v)];
      if (x.side == 0) continue;
      Candidate c{std::numeric_limits<double>::infinity(), 1, v};
      for (const std::int32_t w : {lf.v[(k + 1) % 3], lf.v[(k + 2) % 3]})
        if (region_.verts[std::size_t(w)].side == -x.side) {
          const double d2 = (crossing_x(v, w) - x.x).squaredNorm();
          if (d2 < c.distance2)
            c.distance2 = d2,
            c.fraction = std::sqrt(d2 / (region_.verts[std::size_t(w)].x - x.x).squaredNorm());
        }
      if (c.distance2 < std::numeric_limits<double>::infinity()) candidates[count++] = c;
    }
    if (count == 0) return kNoCandidate;
    // At most three: an insertion sort (stable, as std::sort is on so few; its inlined
    // threshold of 16 draws a false -Warray-bounds from GCC 12 under the sanitizers).
    for (int i = 1; i < count; ++i)
      for (int j = i; j > 0 && candidates[j].distance2 < candidates[j - 1].distance2; --j)
        std::swap(candidates[j], candidates[j - 1]);
    for (int c = 0; c < count; ++c) {
      if (!last && candidates[c].fraction > kAngleSnap) continue;
      auto& side = region_.verts[std::size_t(candidates[c].v)].side;
      const int was = side;
      side = 0;
      const bool mends = pieces_angle(lf.v) >= b;
      side = was;
      if (mends) return candidates[c].v;
    }
    return last ? candidates[0].v : -1;
  }

  // The faces to bisect before classifying afresh: those still unmended (a later snap may have
  // mended one), and those holding a rim chord from a snapped vertex longer than the
  // refinement's limit (a snapped vertex stands for a rim point up to an edge's length away):
  // a clipped face with a rim vertex (the chord to its crossing) and a removed face with two
  // (their edge).
  std::vector<std::int32_t> faces_to_bisect(const std::vector<std::int32_t>& unmended) {
    std::vector<std::int32_t> mend;
    for (const std::int32_t f : unmended)
      if (pieces_angle(region_.faces[std::size_t(f)].v) < bound(region_.faces[std::size_t(f)]))
        mend.push_back(f);
    for (std::size_t f = 0; f < region_.faces.size(); ++f) {
      const Region::LocalFace& lf = region_.faces[f];
      if (lf.depth >= max_depth_) continue;
      const double limit = patches_[std::size_t(lf.patch)].limit;
      if (snapped_chord2(lf) > limit * limit) mend.push_back(std::int32_t(f));
    }
    return mend;
  }

  // The squared length on Π of the rim chord that face lf holds from its snapped vertices
  // (0 when it holds none).
  double snapped_chord2(const Region::LocalFace& lf) const {
    const auto& X = region_.verts;
    int zero = -1, zeros = 0, in = 0, out = 0;
    for (int k = 0; k < 3; ++k) {
      const int side = X[std::size_t(lf.v[k])].side;
      if (side == 0) zero = k, ++zeros;
      in += side<0, out += side> 0;
    }
    if (zeros == 0 || in == 0) return 0;
    if (zeros == 1 && out == 1) {
      const std::int32_t v1 = lf.v[(zero + 1) % 3], v2 = lf.v[(zero + 2) % 3];
      const std::int32_t a = std::min(v1, v2), b = std::max(v1, v2);
      const double t = crossing_t(a, b);
      return (X[std::size_t(lf.v[zero])].q -
              ((1 - t) * X[std::size_t(a)].q + t * X[std::size_t(b)].q))
          .squaredNorm();
    }
    if (zeros == 2) {
      const std::int32_t u = lf.v[(zero + 1) % 3], w = lf.v[(zero + 2) % 3];
      return X[std::size_t(u)].side == 0
                 ? (X[std::size_t(lf.v[zero])].q - X[std::size_t(u)].q).squaredNorm()
                 : (X[std::size_t(lf.v[zero])].q - X[std::size_t(w)].q).squaredNorm();
    }
    return 0;
  }

  Region& region_;
  const std::vector<Patch>& patches_;
  const SkinnedMesh& mesh_;
  const Axis& axis_;
  const DrillOptions& options_;
  DrillResult& result_;
  const double angle_floor_;
  const int max_depth_;
};

}  // namespace

void classify_rim(Region& region, const std::vector<Patch>& patches, const SkinnedMesh& mesh,
                  const Axis& axis, const DrillOptions& options, DrillResult& result) {
  RimClassifier(region, patches, mesh, axis, options, result).run();
}

}  // namespace conform::mesh::drilling
