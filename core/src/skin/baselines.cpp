#include "conform/skin/baselines.hpp"

#include <cmath>

namespace conform::skin {

Eigen::Matrix4d trs_matrix(const Versor& v) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = v.motor.rotation().normalized().toRotationMatrix() * v.scale;
  m.topRightCorner<3, 1>() = v.motor.translation();
  return m;
}

MatrixRig::MatrixRig(const Skeleton& skeleton)
    : skeleton_(&skeleton), global_(skeleton.joints.size()), skin_(skeleton.bones.size()) {
  offsets_.reserve(skeleton.bones.size());
  for (const auto& b : skeleton.bones) offsets_.push_back(trs_matrix(b.offset));
}

void MatrixRig::update(const Pose& pose) {
  const auto& joints = skeleton_->joints;
  for (std::size_t i = 0; i < joints.size(); ++i) {
    const Eigen::Matrix4d local = trs_matrix(pose.local[i]);
    global_[i] = joints[i].parent < 0
                     ? local
                     : Eigen::Matrix4d(global_[static_cast<std::size_t>(joints[i].parent)] * local);
  }
  for (std::size_t n = 0; n < skin_.size(); ++n)
    skin_[n] = global_[static_cast<std::size_t>(skeleton_->bones[n].joint)] * offsets_[n];
}

template <class T>
void MatrixRig::kernels(std::span<Kernel34<T>> out) const {
  for (std::size_t n = 0; n < skin_.size(); ++n)
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) out[n].m[4 * r + c] = static_cast<T>(skin_[n](r, c));
}

template <class T>
void LbsSkinningJob<T>::run() const {
  const auto n = static_cast<std::ptrdiff_t>(input.x.size());
  const int K = input.influences;
  const T* __restrict px = input.x.data();
  const T* __restrict py = input.y.data();
  const T* __restrict pz = input.z.data();
  const std::int32_t* __restrict bones = input.bones.data();
  const T* __restrict weights = input.weights.data();
  const Kernel34<T>* __restrict mats = matrices.data();
  T* __restrict ox = output.x.data();
  T* __restrict oy = output.y.data();
  T* __restrict oz = output.z.data();
#pragma omp parallel for schedule(static) num_threads(skin_threads(threads, input.x.size()))
  for (std::ptrdiff_t v = 0; v < n; ++v) {
    T m[12];
    {
      const T w = weights[v];
      const T* a = mats[bones[v]].m;
      for (int i = 0; i < 12; ++i) m[i] = w * a[i];
    }
    for (int k = 1; k < K; ++k) {
      const T w = weights[k * n + v];
      if (w == T(0)) break;
      const T* a = mats[bones[k * n + v]].m;
      for (int i = 0; i < 12; ++i) m[i] += w * a[i];
    }
    const T x = px[v], y = py[v], z = pz[v];
    ox[v] = m[0] * x + m[1] * y + m[2] * z + m[3];
    oy[v] = m[4] * x + m[5] * y + m[6] * z + m[7];
    oz[v] = m[8] * x + m[9] * y + m[10] * z + m[11];
  }
}

template <class T>
void dq_bones(std::span<const Eigen::Matrix4d> matrices, std::span<DqBone<T>> out) {
  for (std::size_t n = 0; n < matrices.size(); ++n) {
    const Eigen::Matrix3d a = matrices[n].topLeftCorner<3, 3>();
    const double s = std::cbrt(a.determinant());
    const Eigen::Quaterniond q = Eigen::Quaterniond(Eigen::Matrix3d(a / s)).normalized();
    const Eigen::Vector3d t = matrices[n].topRightCorner<3, 1>();
    // dual part ½ (0, t) q
    const Eigen::Quaterniond d = Eigen::Quaterniond(0, t.x(), t.y(), t.z()) * q;
    out[n] = {static_cast<T>(q.w()),       static_cast<T>(q.x()),       static_cast<T>(q.y()),
              static_cast<T>(q.z()),       static_cast<T>(0.5 * d.w()), static_cast<T>(0.5 * d.x()),
              static_cast<T>(0.5 * d.y()), static_cast<T>(0.5 * d.z()), static_cast<T>(s)};
  }
}

template <class T>
void DqSkinningJob<T>::run() const {
  const auto n = static_cast<std::ptrdiff_t>(input.x.size());
  const int K = input.influences;
  const T* __restrict px = input.x.data();
  const T* __restrict py = input.y.data();
  const T* __restrict pz = input.z.data();
  const std::int32_t* __restrict bi = input.bones.data();
  const T* __restrict weights = input.weights.data();
  const DqBone<T>* __restrict dq = bones.data();
  T* __restrict ox = output.x.data();
  T* __restrict oy = output.y.data();
  T* __restrict oz = output.z.data();
#pragma omp parallel for schedule(static) num_threads(skin_threads(threads, input.x.size()))
  for (std::ptrdiff_t v = 0; v < n; ++v) {
    const DqBone<T>& b0 = dq[bi[v]];
    const T w0 = weights[v];
    T qw = w0 * b0.qw, qx = w0 * b0.qx, qy = w0 * b0.qy, qz = w0 * b0.qz;
    T dw = w0 * b0.dw, dx = w0 * b0.dx, dy = w0 * b0.dy, dz = w0 * b0.dz;
    T s = w0 * b0.scale;
    for (int k = 1; k < K; ++k) {
      const T wk = weights[k * n + v];
      if (wk == T(0)) break;
      const DqBone<T>& b = dq[bi[k * n + v]];
      const T w = (b0.qw * b.qw + b0.qx * b.qx + b0.qy * b.qy + b0.qz * b.qz) < T(0) ? -wk : wk;
      qw += w * b.qw, qx += w * b.qx, qy += w * b.qy, qz += w * b.qz;
      dw += w * b.dw, dx += w * b.dx, dy += w * b.dy, dz += w * b.dz;
      s += wk * b.scale;
    }
    // Normalize (Kavan's DLB): divide both parts by |q|.
    const T inv = T(1) / std::sqrt(qw * qw + qx * qx + qy * qy + qz * qz);
    qw *= inv, qx *= inv, qy *= inv, qz *= inv;
    dw *= inv, dx *= inv, dy *= inv, dz *= inv;
    const T x = s * px[v], y = s * py[v], z = s * pz[v];
    // x' = x + 2 q⃗ × (q⃗ × x + qw x) + 2 (qw d⃗ − dw q⃗ + q⃗ × d⃗)
    const T cx = qy * z - qz * y + qw * x;
    const T cy = qz * x - qx * z + qw * y;
    const T cz = qx * y - qy * x + qw * z;
    ox[v] = x + T(2) * (qy * cz - qz * cy) + T(2) * (qw * dx - dw * qx + qy * dz - qz * dy);
    oy[v] = y + T(2) * (qz * cx - qx * cz) + T(2) * (qw * dy - dw * qy + qz * dx - qx * dz);
    oz[v] = z + T(2) * (qx * cy - qy * cx) + T(2) * (qw * dz - dw * qz + qx * dy - qy * dx);
  }
}

template void MatrixRig::kernels<float>(std::span<Kernel34<float>>) const;
template void MatrixRig::kernels<double>(std::span<Kernel34<double>>) const;
template struct LbsSkinningJob<float>;
template struct LbsSkinningJob<double>;
template void dq_bones<float>(std::span<const Eigen::Matrix4d>, std::span<DqBone<float>>);
template void dq_bones<double>(std::span<const Eigen::Matrix4d>, std::span<DqBone<double>>);
template struct DqSkinningJob<float>;
template struct DqSkinningJob<double>;

}  // namespace conform::skin
