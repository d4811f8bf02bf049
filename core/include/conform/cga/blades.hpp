// The 32 basis blades of G(4,1) in the order of the cut/tear/drill paper's Table 2.
// Basis vectors e1, e2, e3, e∞ ("einf"), e0 with e_i² = 1, e∞·e0 = −1, e∞² = e0² = 0.
#pragma once

#include <array>
#include <cstdint>
#include <string_view>

namespace conform::cga {

inline constexpr int kBladeCount = 32;

enum Blade : std::uint8_t {
  kScalar = 0,
  kE1,
  kE2,
  kE3,
  kEinf,
  kE0,  // grade 1
  kE12,
  kE13,
  kE1inf,
  kE10,
  kE23,
  kE2inf,
  kE20,
  kE3inf,
  kE30,
  kEinf0,  // grade 2
  kE123,
  kE12inf,
  kE120,
  kE13inf,
  kE130,
  kE1inf0,
  kE23inf,
  kE230,
  kE2inf0,
  kE3inf0,  // 3
  kE123inf,
  kE1230,
  kE12inf0,
  kE13inf0,
  kE23inf0,  // grade 4
  kE123inf0  // grade 5
};

/// Grade of each blade, indexed by Blade.
inline constexpr std::array<int, kBladeCount> kBladeGrade = {
    0, 1, 1, 1, 1, 1, 2, 2, 2, 2, 2, 2, 2, 2, 2, 2, 3, 3, 3, 3, 3, 3, 3, 3, 3, 3, 4, 4, 4, 4, 4, 5};

/// Basis vectors of each blade as a bit set: bit 0..4 = e1, e2, e3, e∞, e0.
inline constexpr std::array<std::uint8_t, kBladeCount> kBladeVectors = {
    0b00000, 0b00001, 0b00010, 0b00100, 0b01000, 0b10000,  //
    0b00011, 0b00101, 0b01001, 0b10001, 0b00110, 0b01010, 0b10010, 0b01100, 0b10100,
    0b11000,  //
    0b00111, 0b01011, 0b10011, 0b01101, 0b10101, 0b11001, 0b01110, 0b10110, 0b11010,
    0b11100,  //
    0b01111, 0b10111, 0b11011, 0b11101, 0b11110, 0b11111};

/// Canonical printable names ("1", "e1", "e12", "e1inf", "einf0", "e123inf0", ...).
std::string_view blade_name(int blade);

}  // namespace conform::cga
