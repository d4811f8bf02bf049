// Every line of tests/data/cga_vectors.txt (products computed by ganja.js, converted to our
// basis) is recomputed with conform::cga::Multivector<double> and compared to 1e-12 relative.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "conform/cga/multivector.hpp"

namespace cga = conform::cga;
using MV = cga::Multivector<double>;

namespace {

struct OracleLine {
  int line_number;
  std::string op;
  std::vector<MV> inputs;
  MV output;
};

MV parse_coefficients(const std::string& field, int line) {
  std::istringstream in(field);
  MV m;
  for (int i = 0; i < cga::kBladeCount; ++i) {
    if (!(in >> m[i])) ADD_FAILURE() << "line " << line << ": fewer than 32 coefficients";
  }
  return m;
}

std::vector<OracleLine> read_oracle() {
  const std::string path = std::string(CONFORM_TEST_DATA) + "/cga_vectors.txt";
  std::ifstream file(path);
  EXPECT_TRUE(file.good()) << "cannot open " << path;
  std::vector<OracleLine> lines;
  std::string text;
  int number = 0;
  while (std::getline(file, text)) {
    ++number;
    if (text.empty() || text[0] == '#') continue;
    std::vector<std::string> fields;
    std::stringstream ss(text);
    std::string f;
    while (std::getline(ss, f, '|')) fields.push_back(f);
    OracleLine line;
    line.line_number = number;
    std::istringstream(fields.at(0)) >> line.op;
    const int n = std::stoi(fields.at(1));
    EXPECT_EQ(fields.size(), static_cast<std::size_t>(n + 3)) << "line " << number;
    for (int i = 0; i < n; ++i) line.inputs.push_back(parse_coefficients(fields.at(2 + i), number));
    line.output = parse_coefficients(fields.back(), number);
    lines.push_back(line);
  }
  return lines;
}

MV compute(const OracleLine& l) {
  const auto& in = l.inputs;
  if (l.op == "gp") return in[0] * in[1];
  if (l.op == "op") return in[0] ^ in[1];
  if (l.op == "lc") return in[0] << in[1];
  if (l.op == "rev") return in[0].reverse();
  if (l.op == "inv_grade") return in[0].grade_involution();
  if (l.op == "dual") return in[0].dual();
  if (l.op == "versor_inv") {
    auto inv = in[0].versor_inverse();
    EXPECT_TRUE(inv.has_value()) << "line " << l.line_number;
    return inv.value_or(MV());
  }
  if (l.op == "sandwich") {
    auto inv = in[0].versor_inverse();
    EXPECT_TRUE(inv.has_value()) << "line " << l.line_number;
    return in[0] * in[1] * inv.value_or(MV());
  }
  if (l.op == "exp") return cga::exp(in[0]);
  ADD_FAILURE() << "line " << l.line_number << ": unknown op " << l.op;
  return MV();
}

}  // namespace

TEST(CgaOracle, EveryLineMatchesGanja) {
  const auto lines = read_oracle();
  ASSERT_GT(lines.size(), 800u);
  std::map<std::string, int> counts;
  for (const auto& l : lines) {
    const MV got = compute(l);
    const double scale = std::max(1.0, l.output.max_abs());
    for (int i = 0; i < cga::kBladeCount; ++i) {
      EXPECT_NEAR(got[i], l.output[i], 1e-12 * scale)
          << "op " << l.op << " line " << l.line_number << " blade " << cga::blade_name(i);
    }
    ++counts[l.op];
  }
  for (const char* op :
       {"gp", "op", "lc", "rev", "inv_grade", "dual", "versor_inv", "sandwich", "exp"})
    EXPECT_GT(counts[op], 0) << "no oracle line for " << op;
}
