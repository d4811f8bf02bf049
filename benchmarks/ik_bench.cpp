// Arm IK throughput: the readable algebra version, the scalar closed form, and the batched
// closed form (structure of arrays, SIMD) on 1 and 2 threads, in float and double, beside the
// paper's figures: 100 solves in 860 µs on a 1.5 GHz CPU (≈116k solves/s) and the FPGA
// pipeline's one solve per 10 ns at 100 MHz (100M solves/s).
//
// Scalar variants, each an honest general solve: a different target and swivel on every call
// (4096 random reachable targets in turn), the result kept (DoNotOptimize):
//   scalar_q12   the previous formulation (Qs = Q12·Q3, kernel_q12.hpp) with its per-call arm
//                constants, as the library's solve() was before: the in-run baseline
//   scalar       solve(arm, target, φ): arm constants computed on every call
//   arm_ik       ArmIk::solve(target, φ): constants once (the headline scalar figure)
//   arm_ik_cs    ArmIk::solve(target, {cos φ, sin φ}) with the pair precomputed per target
//   latency      ArmIk::solve(target, φ) with each target depending on the previous result
//                (no overlap between consecutive solves: the time of one solve, start to end)
//   latency_q12  the same for the previous formulation
//
// Counters: solves_per_s (rate), x_paper_cpu and x_fpga (that rate over the paper's), and
// x_readable (over the readable version of the same precision, measured earlier in this run).
// A table of the medians over repetitions is printed at the end: solves/s by wall and CPU time,
// ns per solve, and the ratios over the readable version, over the previous formulation
// (scalar_q12; latency_q12 for the latency row), over the paper's CPU and its FPGA.
#include <benchmark/benchmark.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <random>
#include <string>
#include <vector>

#include "conform/ik/arm_ik.hpp"
#include "conform/ik/kernel_q12.hpp"
#include "ratio_reporter.hpp"

namespace ik = conform::ik;

namespace {

constexpr double kPaperCpu = 100.0 / 860e-6;  // solves/s
constexpr double kPaperFpga = 1.0 / 10e-9;

template <class T>
struct Data {
  std::vector<T> x, y, z, phi, cphi, sphi;
  std::vector<T> qw, qx, qy, qz, ew, ex, px, py, pz;
  std::vector<std::uint8_t> st;
};

template <class T>
Data<T>& data(std::size_t n) {
  static std::map<std::size_t, Data<T>> cache;
  auto& d = cache[n];
  if (d.x.size() == n) return d;
  std::mt19937_64 rng(12345);
  std::uniform_real_distribution<double> u(0, 1);
  std::normal_distribution<double> g;
  const double d1 = 0.30, d2 = 0.25, rmin = d1 - d2, rmax = d1 + d2;
  d.cphi.clear(), d.sphi.clear();
  for (auto* v :
       {&d.x, &d.y, &d.z, &d.phi, &d.qw, &d.qx, &d.qy, &d.qz, &d.ew, &d.ex, &d.px, &d.py, &d.pz})
    v->assign(n, T(0));
  d.st.assign(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    Eigen::Vector3d dir(g(rng), g(rng), g(rng));
    dir.normalize();
    const double r =
        std::cbrt(std::pow(rmin, 3) + u(rng) * (std::pow(rmax, 3) - std::pow(rmin, 3)));
    d.x[i] = T(dir.x() * r), d.y[i] = T(dir.y() * r), d.z[i] = T(dir.z() * r);
    d.phi[i] = T((2 * u(rng) - 1) * std::numbers::pi);
    d.cphi.push_back(std::cos(d.phi[i]));
    d.sphi.push_back(std::sin(d.phi[i]));
  }
  return d;
}

// Rates measured with our own clocks, so that ratios between benchmarks can be formed: wall
// time, and the process's CPU time (on a shared machine the second shows what the solver costs
// when it does run; for two threads it is the rate per busy core). Google Benchmark also calls
// each function a few times with fewer iterations to calibrate: only the runs with the largest
// count (the reported repetitions) enter the table.
struct Rate {
  double solves, wall, cpu;  // solves, solves per wall second, per CPU second
};
std::map<std::string, std::vector<Rate>>& rates() {
  static std::map<std::string, std::vector<Rate>> r;
  return r;
}
double cpu_now() {
  timespec t{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return double(t.tv_sec) + 1e-9 * double(t.tv_nsec);
}
double g_readable_rate[2] = {0, 0};  // [0] float, [1] double

template <class T>
constexpr int precision_index() {
  return std::is_same_v<T, double> ? 1 : 0;
}

void finish(benchmark::State& state, const std::string& name, double solves, double seconds,
            double cpu_seconds, int precision) {
  const double rate = solves / seconds;
  rates()[name].push_back({solves, rate, solves / cpu_seconds});
  state.counters["solves_per_s"] = benchmark::Counter(solves, benchmark::Counter::kIsRate);
  state.counters["x_paper_cpu"] = rate / kPaperCpu;
  state.counters["x_fpga"] = rate / kPaperFpga;
  if (g_readable_rate[precision] > 0)
    state.counters["x_readable"] = rate / g_readable_rate[precision];
}

template <class T>
void BM_Readable(benchmark::State& state) {
  auto& d = data<T>(4096);
  const ik::Arm<T> arm;
  std::size_t i = 0, solves = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_now();
  for (auto _ : state) {
    auto s = ik::solve_readable(arm, ik::Vec3<T>(d.x[i], d.y[i], d.z[i]), d.phi[i]);
    benchmark::DoNotOptimize(s);
    i = (i + 1) & 4095;
    ++solves;
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpu_now() - c0;
  g_readable_rate[precision_index<T>()] = double(solves) / secs;
  finish(state, std::string("readable/") + (precision_index<T>() ? "double" : "float"),
         double(solves), secs, cpu, precision_index<T>());
}

// The previous scalar solve, as the library had it: arm check and constants on every call,
// then the Q12·Q3 kernel (kernel_q12.hpp) with std::sqrt and divisions; out of line like the
// library's.
template <class T>
[[gnu::noinline]] ik::Solution<T> solve_q12(const ik::Arm<T>& arm, const ik::Vec3<T>& target,
                                            T swivel) {
  ik::Solution<T> s;
  if (!arm.valid()) {
    s.status = ik::Status::kInvalidInput;
    return s;
  }
  const auto c = ik::detail::q12::KernelConstants<T>::make(
      arm.upper, arm.fore, arm.limits.elbow_min, arm.limits.elbow_max);
  const auto r =
      ik::detail::q12::solve_kernel<T, false>(c, target.x(), target.y(), target.z(), swivel);
  s.qs = ik::Quat<T>(r.qs_w, r.qs_x, r.qs_y, r.qs_z);
  s.qe = ik::Quat<T>(r.qe_w, r.qe_x, T(0), T(0));
  s.elbow = ik::Vec3<T>(r.ex, r.ey, r.ez);
  s.status = static_cast<ik::Status>(r.status);
  return s;
}

enum class Scalar { kQ12, kFree, kSolver, kSolverCosSin, kLatency, kLatencyQ12 };

const char* scalar_name(Scalar v) {
  switch (v) {
    case Scalar::kQ12:
      return "scalar_q12";
    case Scalar::kFree:
      return "scalar";
    case Scalar::kSolver:
      return "arm_ik";
    case Scalar::kSolverCosSin:
      return "arm_ik_cs";
    case Scalar::kLatency:
      return "latency";
    case Scalar::kLatencyQ12:
      return "latency_q12";
  }
  return "?";
}

template <class T, Scalar kVariant>
void BM_Scalar(benchmark::State& state) {
  auto& d = data<T>(4096);
  const ik::Arm<T> arm;
  const ik::ArmIk<T> solver(arm);
  // An opaque zero: the latency variant adds zero·(previous result) to the next target, so
  // that each solve waits for the one before.
  T zero = 0;
  benchmark::DoNotOptimize(zero);
  T carry = 0;
  std::size_t i = 0, solves = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_now();
  for (auto _ : state) {
    const ik::Vec3<T> target(d.x[i] + carry, d.y[i], d.z[i]);
    ik::Solution<T> s;
    if constexpr (kVariant == Scalar::kQ12 || kVariant == Scalar::kLatencyQ12) {
      s = solve_q12(arm, target, d.phi[i]);
    } else if constexpr (kVariant == Scalar::kFree) {
      s = ik::solve(arm, target, d.phi[i]);
    } else if constexpr (kVariant == Scalar::kSolverCosSin) {
      s = solver.solve(target, ik::SwivelCosSin<T>{d.cphi[i], d.sphi[i]});
    } else {
      s = solver.solve(target, d.phi[i]);
    }
    if constexpr (kVariant == Scalar::kLatency || kVariant == Scalar::kLatencyQ12) {
      carry = zero * (s.qs.w() + s.qs.x() + s.qs.y() + s.qs.z());
    } else {
      benchmark::DoNotOptimize(s);
    }
    i = (i + 1) & 4095;
    ++solves;
  }
  benchmark::DoNotOptimize(carry);
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpu_now() - c0;
  state.counters["ns_per_solve"] = 1e9 * secs / double(solves);
  state.counters["cpu_ns_per_solve"] = 1e9 * cpu / double(solves);
  finish(state,
         std::string(scalar_name(kVariant)) + "/" + (precision_index<T>() ? "double" : "float"),
         double(solves), secs, cpu, precision_index<T>());
}

template <class T>
void BM_Batch(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const int threads = static_cast<int>(state.range(1));
  auto& d = data<T>(n);
  ik::BatchSolveJob<T> job;
  job.x = d.x, job.y = d.y, job.z = d.z, job.swivel = d.phi;
  job.qs_w = d.qw, job.qs_x = d.qx, job.qs_y = d.qy, job.qs_z = d.qz;
  job.qe_w = d.ew, job.qe_x = d.ex;
  job.elbow_x = d.px, job.elbow_y = d.py, job.elbow_z = d.pz;
  job.status = d.st;
  job.threads = threads;
  if (!job.Validate()) {
    state.SkipWithError("invalid job");
    return;
  }
  job.Run();  // warm up the thread team and the caches
  std::size_t solves = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_now();
  for (auto _ : state) {
    job.Run();
    benchmark::ClobberMemory();
    solves += n;
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpu_now() - c0;
  finish(state,
         std::string("batch/") + (precision_index<T>() ? "double" : "float") +
             "/n=" + std::to_string(n) + "/threads=" + std::to_string(threads),
         double(solves), secs, cpu, precision_index<T>());
}

// The readable versions run first: the others' x_readable counters use their rates.
BENCHMARK(BM_Readable<float>)->Name("BM_Readable/float");
BENCHMARK(BM_Readable<double>)->Name("BM_Readable/double");
BENCHMARK(BM_Scalar<float, Scalar::kQ12>)->Name("BM_ScalarQ12/float");
BENCHMARK(BM_Scalar<double, Scalar::kQ12>)->Name("BM_ScalarQ12/double");
BENCHMARK(BM_Scalar<float, Scalar::kFree>)->Name("BM_ScalarFast/float");
BENCHMARK(BM_Scalar<double, Scalar::kFree>)->Name("BM_ScalarFast/double");
BENCHMARK(BM_Scalar<float, Scalar::kSolver>)->Name("BM_ArmIk/float");
BENCHMARK(BM_Scalar<double, Scalar::kSolver>)->Name("BM_ArmIk/double");
BENCHMARK(BM_Scalar<float, Scalar::kSolverCosSin>)->Name("BM_ArmIkCosSin/float");
BENCHMARK(BM_Scalar<double, Scalar::kSolverCosSin>)->Name("BM_ArmIkCosSin/double");
BENCHMARK(BM_Scalar<float, Scalar::kLatency>)->Name("BM_ArmIkLatency/float");
BENCHMARK(BM_Scalar<double, Scalar::kLatency>)->Name("BM_ArmIkLatency/double");
BENCHMARK(BM_Scalar<float, Scalar::kLatencyQ12>)->Name("BM_ScalarQ12Latency/float");
BENCHMARK(BM_Scalar<double, Scalar::kLatencyQ12>)->Name("BM_ScalarQ12Latency/double");
BENCHMARK(BM_Batch<float>)
    ->Name("BM_Batch/float")
    ->ArgNames({"n", "threads"})
    ->ArgsProduct({{1 << 14, 1 << 18}, {1, 2}})
    ->UseRealTime();
BENCHMARK(BM_Batch<double>)
    ->Name("BM_Batch/double")
    ->ArgNames({"n", "threads"})
    ->ArgsProduct({{1 << 14, 1 << 18}, {1, 2}})
    ->UseRealTime();

void print_table() {
  std::printf("\nMedian solves/s (paper: CPU %.0f/s, FPGA %.0f/s); ns per solve by wall and CPU\n",
              kPaperCpu, kPaperFpga);
  std::printf("  %-32s %11s %11s %8s %8s %10s %8s %9s %9s\n", "variant", "solves/s", "per CPU-s",
              "ns", "CPU ns", "x readable", "x q12", "x CPU'08", "x FPGA");
  std::map<std::string, std::pair<double, double>> med;  // wall, CPU rate
  for (auto& [name, runs] : rates()) {
    double most = 0;
    for (const Rate& r : runs) most = std::max(most, r.solves);
    std::vector<double> wall, cpu;
    for (const Rate& r : runs)
      if (r.solves == most) wall.push_back(r.wall), cpu.push_back(r.cpu);
    std::sort(wall.begin(), wall.end());
    std::sort(cpu.begin(), cpu.end());
    med[name] = {wall[wall.size() / 2], cpu[cpu.size() / 2]};
  }
  for (const auto& [name, rate] : med) {
    const std::string precision = name.find("double") != std::string::npos ? "double" : "float";
    const auto over = [&](const std::string& base) {
      const auto it = med.find(base + "/" + precision);
      return it != med.end() ? rate.first / it->second.first : 0.0;
    };
    std::printf("  %-32s %11.4g %11.4g %8.1f %8.1f %10.4g %8.3g %9.4g %9.4g\n", name.c_str(),
                rate.first, rate.second, 1e9 / rate.first, 1e9 / rate.second, over("readable"),
                over(name.rfind("latency", 0) == 0 ? "latency_q12" : "scalar_q12"),
                rate.first / kPaperCpu, rate.first / kPaperFpga);
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  // CPU-time ratios of the scalar solves to the previous formulation (printed by the reporter).
  for (const char* p : {"float", "double"}) {
    const std::string base = std::string("BM_ScalarQ12/") + p;
    for (const char* v : {"BM_ScalarFast/", "BM_ArmIk/", "BM_ArmIkCosSin/"})
      conform::bench::add_ratio(v + std::string(p), base);
    conform::bench::add_ratio(std::string("BM_ArmIkLatency/") + p,
                              std::string("BM_ScalarQ12Latency/") + p);
  }
  const int rc = conform::bench::run_with_ratios(argc, argv);
  print_table();
  return rc;
}
