#include "conform/cga/multivector.hpp"

#include <Eigen/Dense>
#include <cctype>
#include <charconv>
#include <cstdlib>
#include <sstream>
#include <stdexcept>

namespace conform::cga {

template <class T>
std::optional<Multivector<T>> Multivector<T>::versor_inverse() const {
  const Multivector rev = reverse();
  const Multivector vv = *this * rev;
  const T s = vv.scalar();
  const T scale = std::max(max_abs() * max_abs(), std::numeric_limits<T>::min());
  // V Ṽ must be a scalar for a versor; reject anything else rather than return garbage.
  const T tolerance = T(1e3) * std::numeric_limits<T>::epsilon() * scale;
  for (int i = 1; i < kBladeCount; ++i)
    if (std::abs(vv[i]) > tolerance) return std::nullopt;
  if (!(std::abs(s) > tolerance) || !std::isfinite(s)) return std::nullopt;
  return rev * (T(1) / s);
}

template <class T>
std::optional<Multivector<T>> Multivector<T>::inverse() const {
  if (!is_finite()) return std::nullopt;
  // Column j of L is a·e_j, so a·x = L x; solve L x = 1 in double.
  Eigen::Matrix<double, 32, 32> left;
  for (int j = 0; j < kBladeCount; ++j) {
    const Multivector<double> col = cast<double>() * Multivector<double>::blade(j);
    for (int i = 0; i < kBladeCount; ++i) left(i, j) = col[i];
  }
  Eigen::FullPivLU<Eigen::Matrix<double, 32, 32>> lu(left);
  const double scale = std::max(left.cwiseAbs().maxCoeff(), 1e-300);
  lu.setThreshold(1e-12);
  if (!lu.isInvertible()) return std::nullopt;
  Eigen::Matrix<double, 32, 1> one = Eigen::Matrix<double, 32, 1>::Zero();
  one[0] = 1.0;
  const Eigen::Matrix<double, 32, 1> x = lu.solve(one);
  const double residual = (left * x - one).cwiseAbs().maxCoeff();
  if (!x.allFinite() || residual > 1e-8 * std::max(1.0, scale * x.cwiseAbs().maxCoeff()))
    return std::nullopt;
  Multivector r;
  for (int i = 0; i < kBladeCount; ++i) r[i] = static_cast<T>(x[i]);
  return r;
}

template <class T>
std::string Multivector<T>::to_string() const {
  std::ostringstream os;
  os.precision(std::numeric_limits<T>::max_digits10);
  bool first = true;
  for (int i = 0; i < kBladeCount; ++i) {
    const T x = (*this)[i];
    if (x == T(0)) continue;
    if (!first)
      os << (x < 0 ? " - " : " + ");
    else if (x < 0)
      os << "-";
    os << std::abs(x);
    if (i != 0) os << "*" << blade_name(i);
    first = false;
  }
  if (first) os << "0";
  return os.str();
}

namespace {

// Parses a blade written as a product of basis vectors ("e12", "e1^einf", "e3inf0", "einf^e0").
// Returns the multivector of that product (with the sign of reordering); throws on bad names.
template <class T>
Multivector<T> parse_blade(std::string_view name, std::string_view term) {
  Multivector<T> result(T(1));
  std::size_t i = 0;
  auto fail = [&]() {
    throw std::invalid_argument("parse_multivector: bad blade name '" + std::string(name) +
                                "' in term '" + std::string(term) + "'");
  };
  bool expect_e = true;
  bool any = false;
  while (i < name.size()) {
    if (name[i] == '^') {
      expect_e = true;
      ++i;
      continue;
    }
    if (expect_e) {
      if (name[i] != 'e') fail();
      ++i;
      expect_e = false;
      if (i >= name.size()) fail();
    }
    int vector = -1;
    if (name.substr(i, 3) == "inf") {
      vector = kEinf;
      i += 3;
    } else if (name[i] == '1' || name[i] == '2' || name[i] == '3') {
      vector = name[i] - '0';
      ++i;
    } else if (name[i] == '0' || name[i] == 'o') {
      vector = kE0;
      ++i;
    } else {
      fail();
    }
    result = result ^ Multivector<T>::blade(vector);
    any = true;
  }
  if (!any) fail();
  if (result.max_abs() == T(0)) {
    throw std::invalid_argument("parse_multivector: blade '" + std::string(name) +
                                "' repeats a basis vector in term '" + std::string(term) + "'");
  }
  return result;
}

}  // namespace

template <class T>
Multivector<T> parse_multivector(std::string_view text) {
  Multivector<T> sum;
  std::size_t i = 0;
  auto skip_space = [&]() {
    while (i < text.size() && std::isspace(static_cast<unsigned char>(text[i]))) ++i;
  };
  bool first = true;
  skip_space();
  if (i == text.size()) throw std::invalid_argument("parse_multivector: empty text");
  while (i < text.size()) {
    skip_space();
    T sign = T(1);
    if (i < text.size() && (text[i] == '+' || text[i] == '-')) {
      if (text[i] == '-') sign = T(-1);
      ++i;
      skip_space();
    } else if (!first) {
      throw std::invalid_argument("parse_multivector: expected '+' or '-' at position " +
                                  std::to_string(i) + " of '" + std::string(text) + "'");
    }
    first = false;
    const std::size_t start = i;
    while (i < text.size() && text[i] != '+' && text[i] != '-') {
      // Exponents such as 1e-5 contain a sign that belongs to the number.
      if ((text[i] == 'e' || text[i] == 'E') && i + 1 < text.size() &&
          (text[i + 1] == '+' || text[i + 1] == '-') && i > start &&
          std::isdigit(static_cast<unsigned char>(text[i - 1]))) {
        i += 2;
        continue;
      }
      ++i;
    }
    std::string term(text.substr(start, i - start));
    while (!term.empty() && std::isspace(static_cast<unsigned char>(term.back()))) term.pop_back();
    if (term.empty())
      throw std::invalid_argument("parse_multivector: empty term in '" + std::string(text) + "'");
    // "coef*blade", "coef blade", "blade" or "coef". The coefficient is read as a number
    // first, so "2e1" is twenty: write "2*e1" or "2 e1".
    T coeff = T(1);
    std::string name = term;
    if (!term.empty() && term[0] != 'e') {
      char* end = nullptr;
      const double v = std::strtod(term.c_str(), &end);
      if (end == term.c_str() || !std::isfinite(v))
        throw std::invalid_argument("parse_multivector: bad coefficient in term '" + term + "'");
      coeff = static_cast<T>(v);
      name = std::string(end);
      std::size_t k = 0;
      while (k < name.size() &&
             (std::isspace(static_cast<unsigned char>(name[k])) || name[k] == '*'))
        ++k;
      name = name.substr(k);
    }
    const Multivector<T> blade = name.empty() ? Multivector<T>(T(1)) : parse_blade<T>(name, term);
    sum += blade * (sign * coeff);
  }
  return sum;
}

template <class T>
Multivector<T> exp(const Multivector<T>& b) {
  // exp(B) = exp(B / 2^k)^(2^k) with ‖B / 2^k‖ ≤ 1/2, Taylor series to machine precision.
  const T size = b.max_abs();
  int squarings = 0;
  T scale = T(1);
  while (size * scale > T(0.5) && squarings < 60) {
    scale *= T(0.5);
    ++squarings;
  }
  const Multivector<T> x = b * scale;
  Multivector<T> term(T(1));
  Multivector<T> sum(T(1));
  for (int n = 1; n < 40; ++n) {
    term = term * x * (T(1) / T(n));
    sum += term;
    if (term.max_abs() < std::numeric_limits<T>::epsilon() * T(1e-3) * sum.max_abs()) break;
  }
  for (int k = 0; k < squarings; ++k) sum = sum * sum;
  return sum;
}

template class Multivector<float>;
template class Multivector<double>;
template Multivector<float> parse_multivector<float>(std::string_view);
template Multivector<double> parse_multivector<double>(std::string_view);
template Multivector<float> exp<float>(const Multivector<float>&);
template Multivector<double> exp<double>(const Multivector<double>&);

}  // namespace conform::cga
