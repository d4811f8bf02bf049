#include "conform/skin/skinning.hpp"

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "conform/cga/point.hpp"

namespace conform::skin {

int InfluenceLists::max_per_vertex() const {
  int best = 0;
  for (std::size_t v = 0; v + 1 < offsets.size(); ++v) {
    int n = 0;
    for (auto i = offsets[v]; i < offsets[v + 1]; ++i)
      n += weights[static_cast<std::size_t>(i)] != 0;
    best = std::max(best, n);
  }
  return best;
}

InfluenceLists InfluenceLists::from_mesh(const mesh::SkinnedMesh& m) {
  InfluenceLists l;
  const auto n = static_cast<std::size_t>(m.vertex_count());
  l.offsets.assign(1, 0);
  l.offsets.reserve(n + 1);
  for (Eigen::Index v = 0; v < m.vertex_count(); ++v) {
    for (int k = 0; k < mesh::kMaxInfluences; ++k)
      if (m.weights(k, v) != 0) {
        l.bones.push_back(m.bones(k, v));
        l.weights.push_back(m.weights(k, v));
      }
    l.offsets.push_back(static_cast<std::int32_t>(l.bones.size()));
  }
  return l;
}

std::string InfluenceLists::validate(std::int32_t bone_count, double tolerance) const {
  if (offsets.empty() || offsets.front() != 0 ||
      static_cast<std::size_t>(offsets.back()) != bones.size() || bones.size() != weights.size())
    return "influence lists are inconsistent";
  // All offsets first: one past the end in the middle of the list ([0, 100, 5] over 5 bones)
  // would otherwise be read before the decrease after it is seen.
  for (std::size_t v = 0; v + 1 < offsets.size(); ++v)
    if (offsets[v + 1] < offsets[v]) return "influence lists are inconsistent";
  for (std::size_t v = 0; v + 1 < offsets.size(); ++v) {
    double sum = 0;
    for (auto i = offsets[v]; i < offsets[v + 1]; ++i) {
      const auto b = bones[static_cast<std::size_t>(i)];
      const double w = weights[static_cast<std::size_t>(i)];
      if (b < 0 || b >= bone_count)
        return "vertex " + std::to_string(v) + " has bone id " + std::to_string(b) +
               ", out of range [0, " + std::to_string(bone_count) + ")";
      if (!std::isfinite(w) || w < 0)
        return "vertex " + std::to_string(v) + " has a NaN, infinite or negative weight";
      sum += w;
    }
    if (offsets[v + 1] > offsets[v] && std::abs(sum - 1) > tolerance)
      return "the weights of vertex " + std::to_string(v) + " sum to " + std::to_string(sum) +
             ", not 1";
  }
  return {};
}

template <class T>
Influences<T> Influences<T>::select(const InfluenceLists& lists, int k) {
  Influences r;
  r.vertex_count = lists.vertex_count();
  r.count = std::max(1, k);
  const auto n = static_cast<std::size_t>(r.vertex_count);
  r.bones.assign(n * static_cast<std::size_t>(r.count), 0);
  r.weights.assign(n * static_cast<std::size_t>(r.count), T(0));
  std::vector<std::int32_t> order;
  for (std::size_t v = 0; v < n; ++v) {
    const auto b = lists.offsets[v], e = lists.offsets[v + 1];
    order.resize(static_cast<std::size_t>(e - b));
    std::iota(order.begin(), order.end(), b);
    std::stable_sort(order.begin(), order.end(), [&](auto i, auto j) {
      return lists.weights[static_cast<std::size_t>(i)] >
             lists.weights[static_cast<std::size_t>(j)];
    });
    const std::size_t used = std::min(order.size(), static_cast<std::size_t>(r.count));
    double sum = 0;
    for (std::size_t s = 0; s < used; ++s) sum += lists.weights[static_cast<std::size_t>(order[s])];
    if (used == 0 || !(sum > 0)) {
      r.weights[v] = T(1);  // slot 0: bone 0 at weight 1
      continue;
    }
    for (std::size_t s = 0; s < used; ++s) {
      const auto i = static_cast<std::size_t>(order[s]);
      r.bones[s * n + v] = lists.bones[i];
      r.weights[s * n + v] = static_cast<T>(lists.weights[i] / sum);
    }
  }
  return r;
}

template <class T>
Influences<T> Influences<T>::from_mesh(const mesh::SkinnedMesh& mesh) {
  Influences r;
  r.vertex_count = mesh.vertex_count();
  r.count = mesh::kMaxInfluences;
  const auto n = static_cast<std::size_t>(r.vertex_count);
  r.bones.resize(n * mesh::kMaxInfluences);
  r.weights.resize(n * mesh::kMaxInfluences);
  for (std::size_t v = 0; v < n; ++v)
    for (std::size_t k = 0; k < std::size_t(mesh::kMaxInfluences); ++k) {
      r.bones[k * n + v] = mesh.bones(Eigen::Index(k), Eigen::Index(v));
      r.weights[k * n + v] = static_cast<T>(mesh.weights(Eigen::Index(k), Eigen::Index(v)));
    }
  return r;
}

template <class T>
SoaPoints<T> SoaPoints<T>::from(Eigen::Ref<const Eigen::Matrix3Xd> p) {
  SoaPoints s;
  s.resize(static_cast<std::size_t>(p.cols()));
  for (Eigen::Index i = 0; i < p.cols(); ++i) {
    const auto u = static_cast<std::size_t>(i);
    s.x[u] = static_cast<T>(p(0, i)), s.y[u] = static_cast<T>(p(1, i)),
    s.z[u] = static_cast<T>(p(2, i));
  }
  return s;
}

template <class T>
void versor_kernels(std::span<const Versor> versors, std::span<Kernel34<T>> out) {
  for (std::size_t n = 0; n < versors.size(); ++n) {
    // down(V up(x) V⁻¹) = d R x + t (versor.hpp): A = d R, b = t. From the motor's components
    // directly, q = (w, v) = (s, −e23, e13, −e12), dual part ε = (ε0, εv) = (−e123∞, −e1∞,
    // −e2∞, −e3∞), N = |q|²:
    //   R = ((w² − |v|²) I + 2 v vᵀ + 2 w [v]×) / N,   t = 2 (w εv − ε0 v + v × εv) / N.
    const auto& m = versors[n].motor;
    const double w = m.s, x = -m.e23, y = m.e13, z = -m.e12;
    const double e0 = -m.e123inf, ex = -m.e1inf, ey = -m.e2inf, ez = -m.e3inf;
    const double inv = 1 / (w * w + x * x + y * y + z * z);
    const double d = versors[n].scale * inv, t2 = 2 * inv;
    T* k = out[n].m;
    k[0] = static_cast<T>((w * w + x * x - y * y - z * z) * d);
    k[1] = static_cast<T>(2 * (x * y - w * z) * d);
    k[2] = static_cast<T>(2 * (x * z + w * y) * d);
    k[3] = static_cast<T>(t2 * (w * ex - e0 * x + (y * ez - z * ey)));
    k[4] = static_cast<T>(2 * (x * y + w * z) * d);
    k[5] = static_cast<T>((w * w - x * x + y * y - z * z) * d);
    k[6] = static_cast<T>(2 * (y * z - w * x) * d);
    k[7] = static_cast<T>(t2 * (w * ey - e0 * y + (z * ex - x * ez)));
    k[8] = static_cast<T>(2 * (x * z - w * y) * d);
    k[9] = static_cast<T>(2 * (y * z + w * x) * d);
    k[10] = static_cast<T>((w * w - x * x - y * y + z * z) * d);
    k[11] = static_cast<T>(t2 * (w * ez - e0 * z + (x * ey - y * ex)));
  }
}

template <class T>
void versor_coefficients(std::span<const Versor> versors, std::span<VersorCoefficients<T>> out) {
  for (std::size_t n = 0; n < versors.size(); ++n) {
    // Unit rotation part, so that blending weights are not skewed by |q|.
    const auto m = versors[n].motor;
    const double inv = 1 / std::sqrt(m.rotation_norm_squared());
    out[n] = {static_cast<T>(m.s * inv),       static_cast<T>(m.e12 * inv),
              static_cast<T>(m.e13 * inv),     static_cast<T>(m.e23 * inv),
              static_cast<T>(m.e1inf * inv),   static_cast<T>(m.e2inf * inv),
              static_cast<T>(m.e3inf * inv),   static_cast<T>(m.e123inf * inv),
              static_cast<T>(versors[n].scale)};
  }
}

template <class T>
std::string validate_skin_io(const SkinInput<T>& in, const SkinOutput<T>& out,
                             std::size_t bone_count) {
  const std::size_t n = in.x.size();
  if (in.y.size() != n || in.z.size() != n) return "input x, y, z differ in size";
  if (out.x.size() != n || out.y.size() != n || out.z.size() != n)
    return "output x, y, z must have the input's size";
  if (in.influences < 1) return "need at least one influence slot";
  const std::size_t slots = n * static_cast<std::size_t>(in.influences);
  if (in.bones.size() != slots || in.weights.size() != slots)
    return "bones and weights must have influences × vertex count entries";
  if (bone_count == 0) return "no bones";
  for (std::size_t i = 0; i < slots; ++i)
    if (in.weights[i] != T(0) &&
        (in.bones[i] < 0 || static_cast<std::size_t>(in.bones[i]) >= bone_count))
      return "bone id " + std::to_string(in.bones[i]) + " out of range [0, " +
             std::to_string(bone_count) + ")";
  return {};
}

int skin_threads(int threads, std::size_t vertex_count) {
  if (vertex_count < 1024) return 1;
  return threads > 0 ? threads : omp_get_max_threads();
}

template <class T>
void CgaSkinningJob<T>::run() const {
  const auto n = static_cast<std::ptrdiff_t>(input.x.size());
  const int K = input.influences;
  const T* __restrict px = input.x.data();
  const T* __restrict py = input.y.data();
  const T* __restrict pz = input.z.data();
  const std::int32_t* __restrict bones = input.bones.data();
  const T* __restrict weights = input.weights.data();
  const Kernel34<T>* __restrict kern = kernels.data();
  T* __restrict ox = output.x.data();
  T* __restrict oy = output.y.data();
  T* __restrict oz = output.z.data();
#pragma omp parallel for schedule(static) num_threads(skin_threads(threads, input.x.size()))
  for (std::ptrdiff_t v = 0; v < n; ++v) {
    const T x = px[v], y = py[v], z = pz[v];
    // w_n down(V_n c V_n⁻¹) = w_n (A_n x + b_n); the first term (always present) starts the
    // sum, the others follow until the first zero weight (sorted: the rest are zero).
    const T* m = kern[bones[v]].m;
    T w = weights[v];
    T ax = w * (m[0] * x + m[1] * y + m[2] * z + m[3]);
    T ay = w * (m[4] * x + m[5] * y + m[6] * z + m[7]);
    T az = w * (m[8] * x + m[9] * y + m[10] * z + m[11]);
    for (int k = 1; k < K; ++k) {
      w = weights[k * n + v];
      if (w == T(0)) break;
      m = kern[bones[k * n + v]].m;
      ax += w * (m[0] * x + m[1] * y + m[2] * z + m[3]);
      ay += w * (m[4] * x + m[5] * y + m[6] * z + m[7]);
      az += w * (m[8] * x + m[9] * y + m[10] * z + m[11]);
    }
    ox[v] = ax, oy[v] = ay, oz[v] = az;
  }
}

template <class T>
void VersorBlendJob<T>::run() const {
  const auto n = static_cast<std::ptrdiff_t>(input.x.size());
  const int K = input.influences;
  const T* __restrict px = input.x.data();
  const T* __restrict py = input.y.data();
  const T* __restrict pz = input.z.data();
  const std::int32_t* __restrict bones = input.bones.data();
  const T* __restrict weights = input.weights.data();
  const VersorCoefficients<T>* __restrict vc = versors.data();
  T* __restrict ox = output.x.data();
  T* __restrict oy = output.y.data();
  T* __restrict oz = output.z.data();
#pragma omp parallel for schedule(static) num_threads(skin_threads(threads, input.x.size()))
  for (std::ptrdiff_t v = 0; v < n; ++v) {
    // Σ ±w_n V_n, each term's sign chosen so that its rotation part agrees with the first
    // influence's (M and −M are the same motion; this keeps the blend on the short path).
    const VersorCoefficients<T>& c0 = vc[bones[v]];
    const T w0 = weights[v];
    T s = w0 * c0.s, e12 = w0 * c0.e12, e13 = w0 * c0.e13, e23 = w0 * c0.e23;
    T e1 = w0 * c0.e1inf, e2 = w0 * c0.e2inf, e3 = w0 * c0.e3inf, e123 = w0 * c0.e123inf;
    T d = w0 * c0.scale;
    for (int k = 1; k < K; ++k) {
      const T wk = weights[k * n + v];
      if (wk == T(0)) break;
      const VersorCoefficients<T>& c = vc[bones[k * n + v]];
      const T w = (c0.s * c.s + c0.e12 * c.e12 + c0.e13 * c.e13 + c0.e23 * c.e23) < T(0) ? -wk : wk;
      s += w * c.s, e12 += w * c.e12, e13 += w * c.e13, e23 += w * c.e23;
      e1 += w * c.e1inf, e2 += w * c.e2inf, e3 += w * c.e3inf, e123 += w * c.e123inf;
      d += wk * c.scale;
    }
    // Down-projection of the blended versor applied to up(x), derived once:
    //   rotation q = (w, qx, qy, qz) = (s, −e23, e13, −e12), dual part ε = (ε0, εv) =
    //   (−e123∞, −e1∞, −e2∞, −e3∞); with n = |q|²:
    //   x' = R(q/|q|) (d x) + t,   t = 2 (w εv − ε0 qv + qv × εv) / n,
    //   R(q) y = y + 2 qv × (qv × y + w y) / n.
    const T qw = s, qx = -e23, qy = e13, qz = -e12;
    const T inv = T(1) / (qw * qw + qx * qx + qy * qy + qz * qz);
    const T ew = -e123, ex = -e1, ey = -e2, ez = -e3;
    const T X = d * px[v], Y = d * py[v], Z = d * pz[v];
    // c = qv × y + w y
    const T cx = qy * Z - qz * Y + qw * X;
    const T cy = qz * X - qx * Z + qw * Y;
    const T cz = qx * Y - qy * X + qw * Z;
    const T two_inv = T(2) * inv;
    const T rx = X + two_inv * (qy * cz - qz * cy);
    const T ry = Y + two_inv * (qz * cx - qx * cz);
    const T rz = Z + two_inv * (qx * cy - qy * cx);
    const T tx = two_inv * (qw * ex - ew * qx + (qy * ez - qz * ey));
    const T ty = two_inv * (qw * ey - ew * qy + (qz * ex - qx * ez));
    const T tz = two_inv * (qw * ez - ew * qz + (qx * ey - qy * ex));
    ox[v] = rx + tx, oy[v] = ry + ty, oz[v] = rz + tz;
  }
}

Eigen::Vector3d skin_point_by_sandwich(std::span<const Versor> versors,
                                       std::span<const std::int32_t> bones,
                                       std::span<const double> weights, const Eigen::Vector3d& x) {
  const cga::Multivector<double> c = cga::Point<double>::up(x).mv();
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < bones.size(); ++k) {
    if (weights[k] == 0) continue;
    const Versor& v = versors[static_cast<std::size_t>(bones[k])];
    const auto vi = v.inverse();
    if (!vi) continue;
    // (M_n,k B_n) c (M_n,k B_n)⁻¹ with the general geometric product, then down-projected.
    const auto moved = cga::down(v.mv() * c * vi->mv());
    if (moved) sum += weights[k] * *moved;
  }
  return sum;
}

template struct Influences<float>;
template struct Influences<double>;
template struct SoaPoints<float>;
template struct SoaPoints<double>;
template void versor_kernels<float>(std::span<const Versor>, std::span<Kernel34<float>>);
template void versor_kernels<double>(std::span<const Versor>, std::span<Kernel34<double>>);
template void versor_coefficients<float>(std::span<const Versor>,
                                         std::span<VersorCoefficients<float>>);
template void versor_coefficients<double>(std::span<const Versor>,
                                          std::span<VersorCoefficients<double>>);
template std::string validate_skin_io<float>(const SkinInput<float>&, const SkinOutput<float>&,
                                             std::size_t);
template std::string validate_skin_io<double>(const SkinInput<double>&, const SkinOutput<double>&,
                                              std::size_t);
template struct CgaSkinningJob<float>;
template struct CgaSkinningJob<double>;
template struct VersorBlendJob<float>;
template struct VersorBlendJob<double>;

}  // namespace conform::skin
