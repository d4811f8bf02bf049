// Posing a frame allocates nothing once the buffers exist: animation sampling into a sized
// pose, the per-bone step and the vertex loop of every mode. Counts global operator new calls.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>

#include "conform/io/import.hpp"
#include "conform/skin/skinner.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// Every unaligned form is replaced, so that whatever one form allocates the matching delete
// frees with the same allocator (a sanitizer's runtime supplies the forms left out, and would
// see memory from its own operator new(nothrow) freed here with free()).
// These replacements are the global allocator, so malloc/free behind new/delete is the pairing
// here; GCC's -Wmismatched-new-delete (when it inlines one into a caller) does not know that.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n ? n : 1)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) {
  return operator new(n);
}
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  return std::malloc(n ? n : 1);
}
void* operator new[](std::size_t n, const std::nothrow_t& tag) noexcept {
  return operator new(n, tag);
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete[](void* p) noexcept {
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept {
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept {
  std::free(p);
}

namespace {

using namespace conform;

TEST(SkinAlloc, FrameAllocatesNothing) {
  const auto model = io::import_model(std::string(CONFORM_ASSIMP_MODELS) + "/FBX/huesitos.fbx");
  skin::Skinner<double> s(model.skeleton, model.mesh.rest, model.influences);
  skin::Pose pose;
  const auto& anim = model.animations.at(0);
  const skin::SkinMode modes[] = {skin::SkinMode::cga, skin::SkinMode::versor,
                                  skin::SkinMode::matrix_lbs, skin::SkinMode::dual_quaternion};
  // Warm-up: sizes the pose, starts OpenMP's threads.
  anim.sample(model.skeleton, 0.1, skin::Blend::log, pose);
  for (auto m : modes) s.skin(pose, m);

  const long before = g_allocations.load();
  for (int f = 0; f < 20; ++f) {
    anim.sample(model.skeleton, 0.07 * f, f % 2 ? skin::Blend::log : skin::Blend::linear, pose);
    for (auto m : modes) s.skin(pose, m);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);

  // The counter works: a skinner construction allocates.
  const long c0 = g_allocations.load();
  skin::Skinner<double> other(model.skeleton, model.mesh.rest, model.influences);
  EXPECT_GT(g_allocations.load() - c0, 0);
}

TEST(SkinAlloc, LargeArmFrameAllocatesNothingWithThreads) {
  const auto model = io::arm_model(2);
  skin::Skinner<double> s(model.skeleton, model.mesh.rest, model.influences);
  s.set_threads(2);
  skin::Pose pose = skin::Pose::rest(model.skeleton);
  pose.apply_local(1, skin::Versor{cga::Motor<double>::from_axis_angle({1, 0, 0}, 1.0), 1.1});
  s.skin(pose, skin::SkinMode::cga);
  const long before = g_allocations.load();
  for (int f = 0; f < 5; ++f) s.skin(pose, skin::SkinMode::cga);
  EXPECT_EQ(g_allocations.load() - before, 0);
}

}  // namespace
