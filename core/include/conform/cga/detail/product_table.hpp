// Sparse multiplication tables of G(4,1) in the null basis, computed once (see product_table.cpp).
#pragma once

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

struct ProductTables {
  std::vector<ProductTerm> geometric;
  std::vector<ProductTerm> outer;
  std::vector<ProductTerm> left_contraction;
  std::vector<ProductTerm> right_contraction;
  std::vector<ProductTerm> scalar;  // only out == 0
};

/// Tables derived from an orthonormal basis e1,e2,e3,e+,e− (e∞ = e− + e+, e0 = ½(e− − e+)).
const ProductTables& product_tables();

}  // namespace conform::cga::detail
