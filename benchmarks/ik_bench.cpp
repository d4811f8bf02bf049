// Arm IK throughput: the readable algebra version, the scalar closed form, and the batched
// closed form (structure of arrays, SIMD) on 1 and 2 threads, in float and double, beside the
// paper's figures: 100 solves in 860 µs on a 1.5 GHz CPU (≈116k solves/s) and the FPGA
// pipeline's one solve per 10 ns at 100 MHz (100M solves/s).
//
// Counters: solves_per_s (rate), x_paper_cpu and x_fpga (that rate over the paper's), and
// x_readable (over the readable version of the same precision, measured earlier in this run).
// A table of the medians over repetitions is printed at the end.
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
#include "ratio_reporter.hpp"

namespace ik = conform::ik;

namespace {

constexpr double kPaperCpu = 100.0 / 860e-6;  // solves/s
constexpr double kPaperFpga = 1.0 / 10e-9;

template <class T>
struct Data {
  std::vector<T> x, y, z, phi;
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
  }
  return d;
}

// Rates measured with our own clocks, so that ratios between benchmarks can be formed: wall
// time, and the process's CPU time (on a shared machine the second shows what the solver costs
// when it does run; for two threads it is the rate per busy core).
std::map<std::string, std::vector<double>>& rates() {
  static std::map<std::string, std::vector<double>> r;
  return r;
}
std::map<std::string, std::vector<double>>& cpu_rates() {
  static std::map<std::string, std::vector<double>> r;
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
  rates()[name].push_back(rate);
  cpu_rates()[name].push_back(solves / cpu_seconds);
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

template <class T>
void BM_ScalarFast(benchmark::State& state) {
  auto& d = data<T>(4096);
  const ik::Arm<T> arm;
  std::size_t i = 0, solves = 0;
  const auto t0 = std::chrono::steady_clock::now();
  const double c0 = cpu_now();
  for (auto _ : state) {
    auto s = ik::solve(arm, ik::Vec3<T>(d.x[i], d.y[i], d.z[i]), d.phi[i]);
    benchmark::DoNotOptimize(s);
    i = (i + 1) & 4095;
    ++solves;
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const double cpu = cpu_now() - c0;
  state.counters["ns_per_solve"] = 1e9 * secs / double(solves);
  finish(state, std::string("scalar/") + (precision_index<T>() ? "double" : "float"),
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
BENCHMARK(BM_ScalarFast<float>)->Name("BM_ScalarFast/float");
BENCHMARK(BM_ScalarFast<double>)->Name("BM_ScalarFast/double");
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
  std::printf("\nMedian solves/s (paper: CPU %.0f/s, FPGA %.0f/s)\n", kPaperCpu, kPaperFpga);
  std::printf("  %-36s %12s %12s %10s %10s %10s\n", "variant", "solves/s", "per CPU-s",
              "x readable", "x CPU'08", "x FPGA");
  const auto medians = [](std::map<std::string, std::vector<double>>& all) {
    std::map<std::string, double> med;
    for (auto& [name, v] : all) {
      std::sort(v.begin(), v.end());
      med[name] = v[v.size() / 2];
    }
    return med;
  };
  const auto med = medians(rates()), cpu = medians(cpu_rates());
  for (const auto& [name, rate] : med) {
    const bool dbl = name.find("double") != std::string::npos;
    const auto base = med.find(dbl ? "readable/double" : "readable/float");
    const double x = base != med.end() ? rate / base->second : 0;
    std::printf("  %-36s %12.4g %12.4g %10.4g %10.4g %10.4g\n", name.c_str(), rate, cpu.at(name), x,
                rate / kPaperCpu, rate / kPaperFpga);
  }
  std::fflush(stdout);
}

}  // namespace

int main(int argc, char** argv) {
  const int rc = conform::bench::run_with_ratios(argc, argv);
  print_table();
  return rc;
}
