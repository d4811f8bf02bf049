// Reading a fuzzer's bytes as typed choices (libFuzzer's FuzzedDataProvider, which only clang
// ships, in the few calls the targets need): every read succeeds, with zeros once the bytes run
// out, so that any input is a valid program of choices. And fuzz_require, the one way a target
// reports a broken property: a message on stderr and abort(), which libFuzzer and the replay
// (replay_main.cpp) both count as a failure.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>

namespace conform::fuzz {

class Bytes {
 public:
  Bytes(const std::uint8_t* data, std::size_t size) : data_(data), size_(size) {}
  bool empty() const { return at_ >= size_; }
  std::uint8_t byte() { return at_ < size_ ? data_[at_++] : 0; }
  /// An integer in [lo, hi].
  int in(int lo, int hi) {
    const std::uint32_t span = static_cast<std::uint32_t>(hi - lo) + 1;
    std::uint32_t v = byte();
    if (span > 256) v = v << 8 | byte();
    return lo + static_cast<int>(v % span);
  }
  /// A fraction in [0, 1] (16 bits).
  double unit() { return in(0, 65535) / 65535.0; }
  /// Raw double bits: NaN, infinities, denormals and huge values as often as the fuzzer likes.
  double raw_double() {
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i) bits = bits << 8 | byte();
    double d;
    std::memcpy(&d, &bits, sizeof d);
    return d;
  }
  /// A number that is usually `typical` (from the caller's range) and sometimes special: zero,
  /// ±huge, NaN, ±infinity, a denormal or raw bits.
  double number(double lo, double hi) {
    switch (in(0, 15)) {
      case 0:
        return 0.0;
      case 1:
        return std::numeric_limits<double>::quiet_NaN();
      case 2:
        return std::numeric_limits<double>::infinity();
      case 3:
        return -1e300;
      case 4:
        return 1e300;
      case 5:
        return std::numeric_limits<double>::denorm_min();
      case 6:
        return raw_double();
      default:
        return lo + (hi - lo) * unit();
    }
  }
  /// The bytes not read yet.
  std::string_view rest() {
    const auto* p = reinterpret_cast<const char*>(data_ + at_);
    const std::size_t n = size_ - std::min(at_, size_);
    at_ = size_;
    return {p, n};
  }

 private:
  const std::uint8_t* data_;
  std::size_t size_;
  std::size_t at_ = 0;
};

/// Aborts with `what` when `ok` is false: a property the target checks does not hold.
inline void fuzz_require(bool ok, const std::string& what) {
  if (ok) return;
  std::fprintf(stderr, "fuzz: property broken: %s\n", what.c_str());
  std::abort();
}

}  // namespace conform::fuzz
