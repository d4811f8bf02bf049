#include "cli/scalpel_csv.hpp"

#include <array>
#include <charconv>
#include <cmath>
#include <stdexcept>

#include "base/bounded_read.hpp"

namespace conform::scenes {
namespace {

constexpr std::array<const char*, 7> kColumns{"t", "ax", "ay", "az", "bx", "by", "bz"};
constexpr std::string_view kHeader = "t,ax,ay,az,bx,by,bz";

std::string_view trim(std::string_view s) {
  const auto first = s.find_first_not_of(" \t\r");
  if (first == std::string_view::npos) return {};
  return s.substr(first, s.find_last_not_of(" \t\r") - first + 1);
}

std::vector<std::string_view> split_cells(std::string_view line) {
  std::vector<std::string_view> cells;
  for (std::size_t start = 0;;) {
    const auto comma = line.find(',', start);
    cells.push_back(trim(line.substr(start, comma - start)));
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

// The whole cell as a finite number, or false. A leading '+' is allowed, as strtod does.
bool finite_number(std::string_view cell, double& value) {
  if (cell.size() > 1 && cell[0] == '+' && cell[1] != '-') cell.remove_prefix(1);
  const char* end = cell.data() + cell.size();
  const auto r = std::from_chars(cell.data(), end, value);
  return !cell.empty() && r.ec == std::errc() && r.ptr == end && std::isfinite(value);
}

// At most 40 characters of a cell, for the message.
std::string shown(std::string_view cell) {
  return cell.size() <= 40 ? std::string(cell) : std::string(cell.substr(0, 37)) + "...";
}

}  // namespace

std::vector<mesh::ScalpelSample> parse_scalpel_csv(std::string_view text, const std::string& file) {
  std::vector<mesh::ScalpelSample> out;
  bool header = false;
  int line_number = 0;
  for (std::size_t start = 0; start < text.size();) {
    const auto newline = text.find('\n', start);
    const std::string_view line = text.substr(start, newline - start);
    start = newline == std::string_view::npos ? text.size() : newline + 1;
    const std::string where = file + ":" + std::to_string(++line_number);
    if (!header) {
      std::string squeezed;
      for (const char ch : line)
        if (ch != ' ' && ch != '\t' && ch != '\r') squeezed += ch;
      if (squeezed != kHeader)
        throw std::runtime_error(where + ": the header must be " + std::string(kHeader) +
                                 ", not '" + shown(trim(line)) + "'");
      header = true;
      continue;
    }
    if (trim(line).empty()) continue;
    const std::vector<std::string_view> cells = split_cells(line);
    if (cells.size() != kColumns.size())
      throw std::runtime_error(where + ": " + std::to_string(cells.size()) +
                               " cells, expected 7 (" + std::string(kHeader) + ")");
    double v[7];
    for (std::size_t k = 0; k < kColumns.size(); ++k)
      if (!finite_number(cells[k], v[k]))
        throw std::runtime_error(where + ": column " + std::to_string(k + 1) + " (" + kColumns[k] +
                                 "): '" + shown(cells[k]) + "' is not a finite number");
    out.push_back({v[0], {v[1], v[2], v[3]}, {v[4], v[5], v[6]}});
  }
  if (!header) throw std::runtime_error(file + ": empty scalpel file (no header)");
  if (out.empty())
    throw std::runtime_error(file + ": no rows: the header " + std::string(kHeader) +
                             " is followed by no sample");
  return out;
}

std::vector<mesh::ScalpelSample> read_scalpel_csv(const std::string& file) {
  return parse_scalpel_csv(read_bounded(file, "scalpel file"), file);
}

}  // namespace conform::scenes
