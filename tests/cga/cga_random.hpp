// Seeded random inputs shared by the algebra's property tests (deterministic per executable).
#pragma once

#include <random>

#include "conform/cga.hpp"

namespace conform::cga::testing {

class Random {
 public:
  explicit Random(std::uint64_t seed) : engine_(seed) {}
  double uniform(double a = -1, double b = 1) {
    return std::uniform_real_distribution<>(a, b)(engine_);
  }
  Vec3<double> vec(double scale = 1) {
    return Vec3<double>(uniform(), uniform(), uniform()) * scale;
  }
  Vec3<double> unit() { return vec().normalized(); }
  Quat<double> quat() {
    return Quat<double>(uniform(), uniform(), uniform(), uniform()).normalized();
  }
  Motor<double> motor(double translation = 5) {
    return Motor<double>::from_rotation_translation(quat(), vec(translation));
  }
  Multivector<double> multivector() {
    Multivector<double> m;
    for (int i = 0; i < kBladeCount; ++i) m[i] = uniform();
    return m;
  }
  Multivector<double> vector() {
    Multivector<double> m;
    for (int i = kE1; i <= kE0; ++i) m[i] = uniform();
    return m;
  }

 private:
  std::mt19937_64 engine_;
};

}  // namespace conform::cga::testing
