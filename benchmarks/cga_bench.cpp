// The algebra's hot kernels against Eigen baselines in the same run:
//   full geometric product           vs Eigen 4×4 · 4×4 (the general-purpose "product" of LBS)
//   motor ∘ motor                    vs Eigen Isometry3d ∘ Isometry3d, and vs quaternion ∘
//   motor · point (one)              vs Eigen 4×4 · vector, Isometry3d · vector, q·v + t
//   motor · point (batched, 1M)      vs Eigen Isometry3d · Matrix3Xd (3×4 on the same points)
//   versor · point with dilation     vs Eigen Affine3d (scaled rotation) · Matrix3Xd
#include <benchmark/benchmark.h>

#include <random>
#include <vector>

#include "conform/cga.hpp"
#include "conform/cga/batch.hpp"
#include "ratio_reporter.hpp"

namespace cga = conform::cga;
using V3 = Eigen::Vector3d;

namespace {

std::mt19937_64 rng(42);
double uniform() {
  return std::uniform_real_distribution<>(-1, 1)(rng);
}
cga::Quat<double> random_quat() {
  return cga::Quat<double>(uniform(), uniform(), uniform(), uniform()).normalized();
}
cga::Motor<double> random_motor() {
  return cga::Motor<double>::from_rotation_translation(random_quat(),
                                                       V3(uniform(), uniform(), uniform()));
}

constexpr int kSmall = 1024;  // independent inputs per iteration for the scalar kernels

void BM_GeometricProduct(benchmark::State& state) {
  std::vector<cga::Multivector<double>> a(kSmall), b(kSmall);
  for (int i = 0; i < kSmall; ++i)
    for (int k = 0; k < 32; ++k) a[i][k] = uniform(), b[i][k] = uniform();
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize(a[i] * b[i]);
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_GeometricProduct);

void BM_Eigen4x4Product(benchmark::State& state) {
  std::vector<Eigen::Matrix4d> a(kSmall), b(kSmall);
  for (int i = 0; i < kSmall; ++i)
    a[i] = Eigen::Matrix4d::Random(), b[i] = Eigen::Matrix4d::Random();
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize((a[i] * b[i]).eval());
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_Eigen4x4Product);

void BM_MotorCompose(benchmark::State& state) {
  std::vector<cga::Motor<double>> a(kSmall), b(kSmall);
  for (int i = 0; i < kSmall; ++i) a[i] = random_motor(), b[i] = random_motor();
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize(a[i] * b[i]);
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_MotorCompose);

void BM_MotorComposeGeneralProduct(benchmark::State& state) {
  std::vector<cga::Multivector<double>> a(kSmall), b(kSmall);
  for (int i = 0; i < kSmall; ++i) a[i] = random_motor().mv(), b[i] = random_motor().mv();
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize(a[i] * b[i]);
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_MotorComposeGeneralProduct);

void BM_EigenIsometryCompose(benchmark::State& state) {
  std::vector<Eigen::Isometry3d> a(kSmall), b(kSmall);
  for (int i = 0; i < kSmall; ++i) {
    a[i] = Eigen::Translation3d(uniform(), uniform(), uniform()) * random_quat();
    b[i] = Eigen::Translation3d(uniform(), uniform(), uniform()) * random_quat();
  }
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize(a[i] * b[i]);
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_EigenIsometryCompose);

// One motor applied to one point, including deriving the motor's coefficients each time (the
// worst case: a fresh motor per point).
void BM_MotorPointSingle(benchmark::State& state) {
  std::vector<cga::Motor<double>> m(kSmall);
  std::vector<V3> p(kSmall);
  for (int i = 0; i < kSmall; ++i) m[i] = random_motor(), p[i] = V3::Random();
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize(m[i].apply(p[i]));
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_MotorPointSingle);

// The same with the per-motor coefficients precomputed (as skinning does once per bone).
void BM_MotorKernelPoint(benchmark::State& state) {
  std::vector<cga::RigidKernel<double>> k(kSmall);
  std::vector<V3> p(kSmall);
  for (int i = 0; i < kSmall; ++i) k[i] = random_motor().kernel(), p[i] = V3::Random();
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize(k[i].apply(p[i]));
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_MotorKernelPoint);

void BM_MotorPointGeneralSandwich(benchmark::State& state) {
  std::vector<cga::Multivector<double>> m(kSmall), minv(kSmall), p(kSmall);
  for (int i = 0; i < kSmall; ++i) {
    m[i] = random_motor().mv();
    minv[i] = m[i].reverse();
    p[i] = cga::Point<double>::up(V3::Random()).mv();
  }
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize(m[i] * p[i] * minv[i]);
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_MotorPointGeneralSandwich);

void BM_QuaternionRotateTranslate(benchmark::State& state) {
  std::vector<cga::Quat<double>> q(kSmall);
  std::vector<V3> t(kSmall), p(kSmall);
  for (int i = 0; i < kSmall; ++i) q[i] = random_quat(), t[i] = V3::Random(), p[i] = V3::Random();
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize((q[i] * p[i] + t[i]).eval());
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_QuaternionRotateTranslate);

void BM_Eigen4x4Vector(benchmark::State& state) {
  std::vector<Eigen::Matrix4d> m(kSmall);
  std::vector<Eigen::Vector4d> p(kSmall);
  for (int i = 0; i < kSmall; ++i)
    m[i] = Eigen::Matrix4d::Random(), p[i] = Eigen::Vector4d::Random();
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize((m[i] * p[i]).eval());
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_Eigen4x4Vector);

void BM_EigenIsometryVector(benchmark::State& state) {
  std::vector<Eigen::Isometry3d> m(kSmall);
  std::vector<V3> p(kSmall);
  for (int i = 0; i < kSmall; ++i) {
    m[i] = Eigen::Translation3d(V3::Random()) * random_quat();
    p[i] = V3::Random();
  }
  for (auto _ : state)
    for (int i = 0; i < kSmall; ++i) benchmark::DoNotOptimize((m[i] * p[i]).eval());
  state.SetItemsProcessed(state.iterations() * kSmall);
}
BENCHMARK(BM_EigenIsometryVector);

// ---- batched: one transform, 1M points ----
constexpr std::size_t kBatch = 1 << 20;

struct Soa {
  std::vector<double> x, y, z, ox, oy, oz;
  Soa() : x(kBatch), y(kBatch), z(kBatch), ox(kBatch), oy(kBatch), oz(kBatch) {
    for (std::size_t i = 0; i < kBatch; ++i) x[i] = uniform(), y[i] = uniform(), z[i] = uniform();
  }
};

void BM_MotorPointBatch(benchmark::State& state) {
  Soa s;
  const auto motor = random_motor();
  for (auto _ : state) {
    const auto k = motor.kernel();  // per-motor coefficients, once per batch
    cga::apply_batch<double>(k, {s.x, s.y, s.z}, {s.ox, s.oy, s.oz});
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_MotorPointBatch)->Unit(benchmark::kMillisecond);

void BM_VersorPointBatch(benchmark::State& state) {
  Soa s;
  const cga::Versor<double> versor{random_motor(), 1.7};
  for (auto _ : state) {
    const auto k = versor.kernel();
    cga::apply_batch<double>(k, {s.x, s.y, s.z}, {s.ox, s.oy, s.oz});
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_VersorPointBatch)->Unit(benchmark::kMillisecond);

void BM_MotorPointBatchFloat(benchmark::State& state) {
  std::vector<float> x(kBatch), y(kBatch), z(kBatch), ox(kBatch), oy(kBatch), oz(kBatch);
  for (std::size_t i = 0; i < kBatch; ++i)
    x[i] = float(uniform()), y[i] = float(uniform()), z[i] = float(uniform());
  const auto motor = cga::Motor<float>::from_rotation_translation(
      random_quat().cast<float>(), Eigen::Vector3f(0.1f, 0.2f, 0.3f));
  for (auto _ : state) {
    cga::apply_batch<float>(motor.kernel(), {x, y, z}, {ox, oy, oz});
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_MotorPointBatchFloat)->Unit(benchmark::kMillisecond);

void BM_EigenIsometryBatchFloat(benchmark::State& state) {
  Eigen::Matrix3Xf in = Eigen::Matrix3Xf::Random(3, kBatch), out(3, kBatch);
  const Eigen::Isometry3f iso =
      Eigen::Translation3f(0.1f, 0.2f, 0.3f) * random_quat().cast<float>();
  for (auto _ : state) {
    out.noalias() = iso * in;
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_EigenIsometryBatchFloat)->Unit(benchmark::kMillisecond);

void BM_EigenIsometryBatch(benchmark::State& state) {
  Eigen::Matrix3Xd in = Eigen::Matrix3Xd::Random(3, kBatch), out(3, kBatch);
  const Eigen::Isometry3d iso = Eigen::Translation3d(V3::Random()) * random_quat();
  for (auto _ : state) {
    out.noalias() = iso * in;
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_EigenIsometryBatch)->Unit(benchmark::kMillisecond);

void BM_EigenAffineScaledBatch(benchmark::State& state) {
  Eigen::Matrix3Xd in = Eigen::Matrix3Xd::Random(3, kBatch), out(3, kBatch);
  const Eigen::Affine3d aff =
      Eigen::Translation3d(V3::Random()) * random_quat() * Eigen::Scaling(1.7);
  for (auto _ : state) {
    out.noalias() = aff * in;
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_EigenAffineScaledBatch)->Unit(benchmark::kMillisecond);

void BM_Eigen4x4Batch(benchmark::State& state) {
  Eigen::Matrix4Xd in = Eigen::Matrix4Xd::Random(4, kBatch), out(4, kBatch);
  in.row(3).setOnes();
  const Eigen::Matrix4d m = (Eigen::Translation3d(V3::Random()) * random_quat()).matrix();
  for (auto _ : state) {
    out.noalias() = m * in;
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(state.iterations() * kBatch);
}
BENCHMARK(BM_Eigen4x4Batch)->Unit(benchmark::kMillisecond);

}  // namespace

int main(int argc, char** argv) {
  using conform::bench::add_ratio;
  add_ratio("BM_GeometricProduct", "BM_Eigen4x4Product");
  add_ratio("BM_MotorCompose", "BM_EigenIsometryCompose");
  add_ratio("BM_MotorCompose", "BM_MotorComposeGeneralProduct");
  add_ratio("BM_MotorPointSingle", "BM_EigenIsometryVector");
  add_ratio("BM_MotorPointSingle", "BM_QuaternionRotateTranslate");
  add_ratio("BM_MotorPointSingle", "BM_Eigen4x4Vector");
  add_ratio("BM_MotorPointSingle", "BM_MotorPointGeneralSandwich");
  add_ratio("BM_MotorKernelPoint", "BM_EigenIsometryVector");
  add_ratio("BM_MotorPointBatchFloat", "BM_EigenIsometryBatchFloat",
            "vs BM_EigenIsometryBatchFloat (goal <= 1.0)");
  add_ratio("BM_MotorPointBatch", "BM_EigenIsometryBatch",
            "vs BM_EigenIsometryBatch (goal <= 1.0)");
  add_ratio("BM_MotorPointBatch", "BM_Eigen4x4Batch");
  add_ratio("BM_VersorPointBatch", "BM_EigenAffineScaledBatch");
  return conform::bench::run_with_ratios(argc, argv);
}
