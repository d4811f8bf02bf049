// Builds the null-basis multiplication tables from the diagonal-metric algebra.
//
// In the orthonormal basis o1..o5 = e1, e2, e3, e+, e− (metric +,+,+,+,−) the product of two
// basis blades is one blade with a sign (bit sets, reordering count, metric). Each null-basis
// blade is a wedge of vectors e1, e2, e3, e∞ = o5 + o4, e0 = ½(o5 − o4), i.e. a column of a
// 32×32 change-of-basis matrix C. Then null(a)·null(b) = C⁻¹ · ortho(C a · C b). Contractions
// and the outer product keep the terms whose grade is |gb − ga|, ga + gb: the change of basis
// maps vectors to vectors, so it preserves grades.
#include <Eigen/Dense>
#include <array>
#include <bit>
#include <cmath>
#include <string_view>

#include "conform/cga/blades.hpp"
#include "conform/cga/detail/product_table.hpp"

namespace conform::cga {

std::string_view blade_name(int blade) {
  static constexpr std::array<std::string_view, kBladeCount> kNames = {
      "1",      "e1",     "e2",      "e3",     "einf",    "e0",      "e12",     "e13",
      "e1inf",  "e10",    "e23",     "e2inf",  "e20",     "e3inf",   "e30",     "einf0",
      "e123",   "e12inf", "e120",    "e13inf", "e130",    "e1inf0",  "e23inf",  "e230",
      "e2inf0", "e3inf0", "e123inf", "e1230",  "e12inf0", "e13inf0", "e23inf0", "e123inf0"};
  if (blade < 0 || blade >= kBladeCount) return "?";
  return kNames[static_cast<std::size_t>(blade)];
}

namespace detail {
namespace {

using Ortho = Eigen::Matrix<double, 32, 1>;  // indexed by orthonormal bit set

// Sign of moving the vectors of blade b past those of blade a into canonical order.
int reorder_sign(unsigned a, unsigned b) {
  int swaps = 0;
  for (a >>= 1; a != 0; a >>= 1) swaps += std::popcount(a & b);
  return (swaps & 1) ? -1 : 1;
}

// Geometric product of orthonormal blades: sign and result bit set.
double ortho_gp_sign(unsigned a, unsigned b) {
  double s = reorder_sign(a, b);
  if ((a & b) & 0b10000u) s = -s;  // o5 = e− squares to −1
  return s;
}

Ortho ortho_gp(const Ortho& x, const Ortho& y) {
  Ortho r = Ortho::Zero();
  for (unsigned a = 0; a < 32; ++a) {
    if (x[a] == 0.0) continue;
    for (unsigned b = 0; b < 32; ++b) {
      if (y[b] == 0.0) continue;
      r[a ^ b] += ortho_gp_sign(a, b) * x[a] * y[b];
    }
  }
  return r;
}

Ortho ortho_outer(const Ortho& x, const Ortho& y) {
  Ortho r = Ortho::Zero();
  for (unsigned a = 0; a < 32; ++a)
    for (unsigned b = 0; b < 32; ++b)
      if ((a & b) == 0) r[a | b] += reorder_sign(a, b) * x[a] * y[b];
  return r;
}

// Orthonormal coefficients of null basis vector i (0..4 = e1, e2, e3, e∞, e0).
Ortho null_vector(int i) {
  Ortho v = Ortho::Zero();
  switch (i) {
    case 0:
      v[0b00001] = 1;
      break;
    case 1:
      v[0b00010] = 1;
      break;
    case 2:
      v[0b00100] = 1;
      break;
    case 3:
      v[0b01000] = 1;
      v[0b10000] = 1;
      break;  // e∞ = e+ + e−
    case 4:
      v[0b01000] = -0.5;
      v[0b10000] = 0.5;
      break;  // e0 = ½(e− − e+)
  }
  return v;
}

double snap(double c) {
  // Every coefficient is a small dyadic rational; remove the round-off of the inverse.
  const double snapped = std::round(c * 64.0) / 64.0;
  return std::abs(snapped) < 1e-9 ? 0.0 : snapped;
}

ProductTables build() {
  Eigen::Matrix<double, 32, 32> change;  // column j = null blade j in the orthonormal basis
  for (int j = 0; j < kBladeCount; ++j) {
    Ortho blade = Ortho::Zero();
    blade[0] = 1;
    for (int i = 0; i < 5; ++i)
      if (kBladeVectors[static_cast<std::size_t>(j)] & (1u << i))
        blade = ortho_outer(blade, null_vector(i));
    change.col(j) = blade;
  }
  const Eigen::Matrix<double, 32, 32> inverse = change.inverse();

  ProductTables t;
  for (int a = 0; a < kBladeCount; ++a) {
    for (int b = 0; b < kBladeCount; ++b) {
      const Ortho product = ortho_gp(change.col(a), change.col(b));
      const Ortho null_product = inverse * product;
      const int ga = kBladeGrade[static_cast<std::size_t>(a)];
      const int gb = kBladeGrade[static_cast<std::size_t>(b)];
      for (int k = 0; k < kBladeCount; ++k) {
        const double c = snap(null_product[k]);
        if (c == 0.0) continue;
        const int gk = kBladeGrade[static_cast<std::size_t>(k)];
        const ProductTerm term{static_cast<std::uint8_t>(a), static_cast<std::uint8_t>(b),
                               static_cast<std::uint8_t>(k), c};
        t.geometric.terms.push_back(term);
        if (gk == ga + gb) t.outer.terms.push_back(term);
        if (ga <= gb && gk == gb - ga) t.left_contraction.terms.push_back(term);
        if (ga >= gb && gk == ga - gb) t.right_contraction.terms.push_back(term);
        if (gk == 0) t.scalar.terms.push_back(term);
      }
    }
  }
  for (ProductTable* table :
       {&t.geometric, &t.outer, &t.left_contraction, &t.right_contraction, &t.scalar}) {
    // Terms were appended in increasing lhs order.
    std::size_t k = 0;
    for (int lhs = 0; lhs <= kBladeCount; ++lhs) {
      while (k < table->terms.size() && table->terms[k].lhs < lhs) ++k;
      table->lhs_begin[static_cast<std::size_t>(lhs)] = static_cast<std::uint16_t>(k);
    }
    table->lhs_begin[kBladeCount] = static_cast<std::uint16_t>(table->terms.size());
  }
  return t;
}

}  // namespace

const ProductTables& product_tables() {
  static const ProductTables tables = build();
  return tables;
}

}  // namespace detail
}  // namespace conform::cga
