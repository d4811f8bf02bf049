// The C++ side of the Python binding's overhead: a loop of 1000 steps of the procedural arm
// (resolution 1, the default membrane material) in a soft world with gravity and a ground (a
// static box whose top is y = -0.5), exactly what benchmarks/python_step_loop.py runs through the
// `conform` module (World(), add_arm(), 1000 x step(1/60)); that script runs this program and
// prints the ratio. The baseline here is the same loop without skinned body, the world's own cost.
#include <benchmark/benchmark.h>

#include <memory>

#include "conform/bullet/plugin.hpp"
#include "conform/bullet/soft_world.hpp"
#include "conform/skin/procedural_arm.hpp"

using namespace conform;

namespace {

constexpr int kSteps = 1000;

struct ArmWorld {
  bullet::SoftWorld soft{btVector3(0, btScalar(-9.81), 0)};
  btBoxShape ground_shape{btVector3(50, btScalar(0.05), 50)};  // the top at y = -0.5
  btDefaultMotionState ground_motion{
      btTransform(btQuaternion::getIdentity(), btVector3(0, btScalar(-0.55), 0))};
  btRigidBody ground{btRigidBody::btRigidBodyConstructionInfo(0, &ground_motion, &ground_shape)};
  std::unique_ptr<bullet::Plugin> plugin;
  explicit ArmWorld(bool with_arm) {
    soft.world.addRigidBody(&ground);
    plugin = std::make_unique<bullet::Plugin>(soft.world);
    if (with_arm) {
      const skin::Arm arm = skin::make_arm(1);
      plugin->add_skinned_body(arm.mesh, arm.skeleton, bullet::Material{});
    }
  }
  ~ArmWorld() {
    plugin.reset();
    soft.world.removeRigidBody(&ground);
  }
};

void run_loop(benchmark::State& state, bool with_arm) {
  for (auto _ : state) {
    state.PauseTiming();
    auto w = std::make_unique<ArmWorld>(with_arm);
    state.ResumeTiming();
    for (int i = 0; i < kSteps; ++i) w->soft.step(1.0 / 60, 1);
    state.PauseTiming();
    w.reset();
    state.ResumeTiming();
  }
  state.counters["ms_per_step"] =
      benchmark::Counter(double(state.iterations()) * kSteps / 1e3,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_ArmStepLoop(benchmark::State& state) {
  run_loop(state, true);
}
BENCHMARK(BM_ArmStepLoop)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->UseRealTime();

void BM_EmptyWorldStepLoop(benchmark::State& state) {
  run_loop(state, false);
}
BENCHMARK(BM_EmptyWorldStepLoop)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
