// Sparse multiplication tables of G(4,1) in the null basis, computed once (see product_table.cpp).
#pragma once

#include <array>
#include <cstdint>
#include <vector>

namespace conform::cga::detail {

/// One term of a bilinear product: result[out] += coeff · a[lhs] · b[rhs].
struct ProductTerm {
  std::uint8_t lhs;
  std::uint8_t rhs;
  std::uint8_t out;
  double coeff;
};

/// Terms sorted by lhs; terms[lhs_begin[i] .. lhs_begin[i + 1]) have lhs == i, so a product
/// skips every zero coefficient of its left operand (most elements are sparse).
struct ProductTable {
  std::vector<ProductTerm> terms;
  std::array<std::uint16_t, 33> lhs_begin{};
};

struct ProductTables {
  ProductTable geometric;
  ProductTable outer;
  ProductTable left_contraction;
  ProductTable right_contraction;
  ProductTable scalar;  // only out == 0
};

/// Tables derived from an orthonormal basis e1,e2,e3,e+,e− (e∞ = e− + e+, e0 = ½(e− − e+)).
const ProductTables& product_tables();

}  // namespace conform::cga::detail
