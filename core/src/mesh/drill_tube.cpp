#include "drill_tube.hpp"

#include <cmath>
#include <numbers>
#include <string>

namespace conform::mesh::drilling {

namespace {

constexpr double kPi = std::numbers::pi;
double wrap(double a) {
  return std::remainder(a, 2 * kPi);
}

// The tube walls of one drill: each entry/exit pair of holes joined in turn.
class TubeBuilder {
 public:
  TubeBuilder(const Outcome& out, const Axis& axis, double ring_spacing, TopologyChange& change,
              std::vector<Eigen::Vector3d>& new_x, EdgeMap& rim_edges, EdgeMap& in_a,
              DrillResult& result)
      : out_(out),
        axis_(axis),
        ring_spacing_(ring_spacing),
        change_(change),
        new_x_(new_x),
        rim_edges_(rim_edges),
        in_a_(in_a),
        result_(result),
        nv0_(change.base_vertex_count) {}

  void run(const std::vector<Patch>& patches) {
    std::vector<const Patch*> cut;
    for (const auto& p : patches)
      if (p.cut) cut.push_back(&p);
    std::sort(cut.begin(), cut.end(), [](const Patch* a, const Patch* b) { return a->t < b->t; });
    for (std::size_t i = 0; i + 1 < cut.size();) {
      const Patch& pa = *cut[i];
      const Patch& pb = *cut[i + 1];
      if (!pa.entering || pb.entering) {
        ++i;
        continue;
      }
      i += 2;
      join(pa, pb);
    }
    if (!faces_.empty())
      change_.new_surface.push_back({static_cast<std::int32_t>(change_.added_faces.size()),
                                     static_cast<std::int32_t>(faces_.size()), FaceKind::tube});
    change_.added_faces.insert(change_.added_faces.end(), faces_.begin(), faces_.end());
  }

 private:
  Eigen::Vector3d pos(std::int32_t v) const { return out_.pos(v); }
  // The rim vertices' angles about the axis, in the frame of Π.
  double angle(std::int32_t v) const {
    const Eigen::Vector2d q = axis_.project(pos(v));
    return std::atan2(q.y(), q.x());
  }
  // Cumulative turning along a closed loop from its first vertex (loop.size() + 1 values).
  std::vector<double> turning(const std::vector<std::int32_t>& loop) const {
    std::vector<double> cum(loop.size() + 1, 0.0);
    double previous = angle(loop[0]), first = previous;
    for (std::size_t k = 0; k < loop.size(); ++k) {
      const double next = k + 1 < loop.size() ? angle(loop[k + 1]) : first;
      cum[k + 1] = cum[k] + wrap(next - previous);
      previous = next;
    }
    return cum;
  }
  // Both loops wind once about the axis the same way.
  static bool winds_with(const std::vector<double>& a, const std::vector<double>& b) {
    return std::abs(std::abs(a.back()) - 2 * kPi) <= 1e-6 && std::abs(a.back() - b.back()) <= 1e-6;
  }
  // The winding number of a loop of positions about the axis (crossings of the ray along e1,
  // signed): no trigonometry, for the rings.
  static int winding(const std::vector<Eigen::Vector2d>& q) {
    int w = 0;
    for (std::size_t k = 0; k < q.size(); ++k) {
      const Eigen::Vector2d &p0 = q[k], &p1 = q[(k + 1) % q.size()];
      const double cross = p0.x() * p1.y() - p0.y() * p1.x();
      if (p0.y() <= 0 && p1.y() > 0 && cross > 0) ++w;
      if (p1.y() <= 0 && p0.y() > 0 && cross < 0) --w;
    }
    return w;
  }
  void fail(const std::string& why) {
    if (!result_.message.empty()) result_.message += "; ";
    result_.message += why;
  }

  // The strip between loops P and Q (Q[0] the nearest of Q to P[0] in angle), merged by angle.
  void zip(const std::vector<std::int32_t>& P, const std::vector<double>& alpha,
           const std::vector<std::int32_t>& Q, const std::vector<double>& beta) {
    const double sign = alpha.back() > 0 ? 1 : -1, delta = wrap(angle(Q[0]) - angle(P[0]));
    const std::size_t n = P.size(), m = Q.size();
    for (std::size_t ia = 0, jb = 0; ia < n || jb < m;) {
      const bool along_p =
          jb == m || (ia < n && sign * alpha[ia + 1] <= sign * (delta + beta[jb + 1]));
      if (along_p) {
        faces_.push_back({P[ia], P[(ia + 1) % n], Q[jb % m]});
        ++ia;
      } else {
        faces_.push_back({Q[(jb + 1) % m], Q[jb], P[ia % n]});
        ++jb;
      }
    }
  }
  // The strip between two rings of equal size whose k-th vertices correspond (on one segment
  // between the rims): quads, each split along its shorter diagonal.
  void ladder(const std::vector<std::int32_t>& P, const std::vector<std::int32_t>& Q) {
    const std::size_t n = P.size();
    for (std::size_t k = 0; k < n; ++k) {
      const std::int32_t p0 = P[k], p1 = P[(k + 1) % n], q0 = Q[k], q1 = Q[(k + 1) % n];
      if ((pos(p1) - pos(q0)).squaredNorm() <= (pos(p0) - pos(q1)).squaredNorm())
        faces_.push_back({p0, p1, q0}), faces_.push_back({q1, q0, p1});
      else
        faces_.push_back({p0, p1, q1}), faces_.push_back({q1, q0, p0});
    }
  }

  // One entry rim and the next exit rim, as loops A and B that turn the same way about the
  // axis, B starting at the vertex nearest A[0] in angle.
  struct Rims {
    std::vector<std::int32_t> A, B;
    std::vector<double> alpha, beta;  // their cumulative turning
    double sign = 1, delta = 0;       // the turning's sign; B[0]'s angle from A[0]
  };

  // The tube between entry hole pa and exit hole pb, or a message why it is left open.
  void join(const Patch& pa, const Patch& pb) {
    if (pa.rim.empty() || pb.rim.empty()) {
      fail("tube: a rim is not one simple loop of rim vertices");
      return;
    }
    const Rims rims = align(pa, pb);
    if (!winds_with(rims.alpha, rims.beta)) {
      fail("tube: the rims do not wind once around the axis in matching directions");
      return;
    }
    // The tube must only add edges: the rims share no vertex; along the rims the strip uses
    // the reverse of a boundary half-edge (checked below), and across it edges that the
    // changed mesh does not have (ring vertices are new: no edge has them).
    bool ok = true;
    in_a_.clear();
    for (auto v : rims.A) in_a_.insert(0, v, 1);
    for (auto v : rims.B) ok = ok && in_a_.find(0, v) < 0;
    const std::size_t first_ring = change_.new_vertices.size();
    std::vector<std::vector<std::int32_t>> loops{rims.A};
    std::size_t a_family = 1;  // loops[0, a_family) have A's size and correspondence
    if (ok && ring_spacing_ > 0) add_rings(rims, first_ring, loops, a_family);
    loops.push_back(rims.B);
    const std::size_t first_face = faces_.size();
    for (std::size_t k = 0; ok && k + 1 < loops.size(); ++k) {
      if (k + 1 < a_family || k >= a_family) {
        ladder(loops[k], loops[k + 1]);
        continue;
      }
      // Between the last ring of A's spacing and the first of B's: merged by angle.
      const auto& P = loops[k];
      const auto& Q = loops[k + 1];
      zip(P, k == 0 ? rims.alpha : turning(P), Q, k + 2 == loops.size() ? rims.beta : turning(Q));
    }
    if (!ok || !only_new_edges(first_face, first_ring)) {
      faces_.resize(first_face);
      change_.new_vertices.resize(first_ring);
      new_x_.resize(first_ring);
      fail("tube: the rims share vertices or edges");
      return;
    }
    // Later tubes see this one's edges between rim vertices (ring vertices are on no rim).
    const std::int32_t rings_from = nv0_ + std::int32_t(first_ring);
    for (std::size_t f = first_face; f < faces_.size(); ++f)
      for (int e = 0; e < 3; ++e) {
        const std::int32_t x = faces_[f][e], y = faces_[f][(e + 1) % 3];
        if (x < rings_from && y < rings_from) rim_edges_.insert(x, y, 1);
      }
    result_.tube_faces += static_cast<std::int32_t>(faces_.size() - first_face);
    ++result_.tubes;
  }

  // The tube runs along the entry rim against its boundary order and along the exit rim in
  // its boundary order: both then turn the same way about the axis.
  Rims align(const Patch& pa, const Patch& pb) const {
    Rims r;
    r.A.assign(pa.rim.rbegin(), pa.rim.rend());
    const double a0 = angle(r.A[0]);
    std::size_t j0 = 0;
    for (std::size_t j = 1; j < pb.rim.size(); ++j)
      if (std::abs(wrap(angle(pb.rim[j]) - a0)) < std::abs(wrap(angle(pb.rim[j0]) - a0))) j0 = j;
    r.B.assign(pb.rim.begin() + static_cast<std::ptrdiff_t>(j0), pb.rim.end());
    r.B.insert(r.B.end(), pb.rim.begin(), pb.rim.begin() + static_cast<std::ptrdiff_t>(j0));
    r.alpha = turning(r.A), r.beta = turning(r.B);
    r.sign = r.alpha.back() > 0 ? 1 : -1, r.delta = wrap(angle(r.B[0]) - a0);
    return r;
  }

  // Rings: each rim vertex's partner on the other rim is the one nearest in turning; ring k
  // of K lies at s = k / (K + 1) on the segments from the nearer rim's vertices to their
  // partners, so that it has that rim's spacing. K makes the rings at most ring_spacing ×
  // the rims' mean edge apart (without them one triangle spans the whole wall). A ring that
  // folds back drops them all.
  void add_rings(const Rims& r, std::size_t first_ring,
                 std::vector<std::vector<std::int32_t>>& loops, std::size_t& a_family) {
    const auto& A = r.A;
    const auto& B = r.B;
    const double sign = r.sign, delta = r.delta;
    const std::size_t n = A.size(), m = B.size();
    std::vector<std::size_t> partner_a(n), partner_b(m);
    for (std::size_t ia = 0, jb = 0; ia < n; ++ia) {
      while (jb + 1 < m && std::abs(sign * (delta + r.beta[jb + 1]) - sign * r.alpha[ia]) <
                               std::abs(sign * (delta + r.beta[jb]) - sign * r.alpha[ia]))
        ++jb;
      partner_a[ia] = jb;
    }
    for (std::size_t jb = 0, ia = 0; jb < m; ++jb) {
      while (ia + 1 < n && std::abs(sign * r.alpha[ia + 1] - sign * (delta + r.beta[jb])) <
                               std::abs(sign * r.alpha[ia] - sign * (delta + r.beta[jb])))
        ++ia;
      partner_b[jb] = ia;
    }
    double rims = 0, across = 0;
    for (std::size_t k = 0; k < n; ++k) {
      rims += (pos(A[(k + 1) % n]) - pos(A[k])).norm();
      across += (pos(B[partner_a[k]]) - pos(A[k])).norm() / double(n);
    }
    for (std::size_t k = 0; k < m; ++k) rims += (pos(B[(k + 1) % m]) - pos(B[k])).norm();
    const double step = ring_spacing_ * rims / double(n + m);
    const int rings = std::min(64, std::max(0, int(std::ceil(across / step)) - 1));
    std::vector<Eigen::Vector2d> q;
    for (int k = 1; k <= rings; ++k) {
      const double s = double(k) / (rings + 1);
      const bool from_a = s <= 0.5;
      std::vector<std::int32_t> ring;
      q.clear();
      for (std::size_t j = 0; j < (from_a ? n : m); ++j) {
        const std::int32_t a = from_a ? A[j] : A[partner_b[j]];
        const std::int32_t b = from_a ? B[partner_a[j]] : B[j];
        ring.push_back(nv0_ + std::int32_t(change_.new_vertices.size()));
        change_.new_vertices.push_back(NewVertex::on_edge(a, b, s));
        new_x_.push_back((1 - s) * pos(a) + s * pos(b));
        q.push_back(axis_.project(new_x_.back()));
      }
      if (winding(q) != int(sign)) {  // a ring folds back: no rings for this tube
        change_.new_vertices.resize(first_ring);
        new_x_.resize(first_ring);
        loops.resize(1);
        a_family = 1;
        return;
      }
      loops.push_back(std::move(ring));
      if (from_a) a_family = loops.size();
    }
  }

  // The strip's edges from faces_[first_face] on are new to the changed mesh (edges at ring
  // vertices always are).
  bool only_new_edges(std::size_t first_face, std::size_t first_ring) const {
    for (std::size_t f = first_face; f < faces_.size(); ++f)
      for (int e = 0; e < 3; ++e) {
        const std::int32_t x = faces_[f][e], y = faces_[f][(e + 1) % 3];
        if (x >= nv0_ + std::int32_t(first_ring) || y >= nv0_ + std::int32_t(first_ring))
          continue;  // a ring vertex: a new edge
        const bool across = (in_a_.find(0, x) >= 0) != (in_a_.find(0, y) >= 0);
        if (out_.has(x, y) || (across && out_.has(y, x))) return false;
      }
    return true;
  }

  const Outcome& out_;
  const Axis& axis_;
  const double ring_spacing_;
  TopologyChange& change_;
  std::vector<Eigen::Vector3d>& new_x_;
  EdgeMap& rim_edges_;
  EdgeMap& in_a_;
  DrillResult& result_;
  const std::int32_t nv0_;
  std::vector<Face> faces_;  // the tube walls' faces, appended to the change at the end
};

}  // namespace

void add_tubes(const Outcome& out, const Axis& axis, const std::vector<Patch>& patches,
               double ring_spacing, TopologyChange& change, std::vector<Eigen::Vector3d>& new_x,
               EdgeMap& rim_edges, EdgeMap& in_a, DrillResult& result) {
  TubeBuilder(out, axis, ring_spacing, change, new_x, rim_edges, in_a, result).run(patches);
}

}  // namespace conform::mesh::drilling
