#include "sweep/sweep_table.hpp"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <set>

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

void flatten(const Json& j, const std::string& prefix, std::map<std::string, double>& out) {
  for (auto it = j.begin(); it != j.end(); ++it) {
    const std::string key = prefix + it.key();
    if (it->is_object())
      flatten(*it, key + ".", out);
    else if (it->is_boolean())
      out[key] = it->get<bool>() ? 1.0 : 0.0;
    else if (it->is_number())
      out[key] = it->get<double>();
  }
}

// RFC 4180: a field with a comma, quote or line break is quoted, quotes doubled.
std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n\r") == std::string::npos) return s;
  std::string out = "\"";
  for (char c : s) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);  // as the runs' metrics.csv
  return buf;
}

}  // namespace

std::optional<double> SweepTable::value(const SweepRow& row, const std::string& column) const {
  const auto it = row.numbers.find(column);
  if (it == row.numbers.end()) return std::nullopt;
  return it->second;
}

SweepTable gather_table(const SweepSpec& spec, const fs::path& dir) {
  SweepTable t;
  std::set<std::string> seen;
  for (const auto& p : spec.points) {
    const fs::path folder = point_dir(dir, p.index);
    SweepRow row;
    row.point = &p;
    row.status = read_status(dir, p.index);
    row.seed = p.run_seed;
    if (row.status.state == PointStatus::State::Missing) {
      t.missing.push_back(p.index);
      continue;
    }
    if (row.status.state == PointStatus::State::Done) {
      std::ifstream in(folder / "summary.json");
      const Json s = Json::parse(in, nullptr, false);
      row.seed = s.value("seed", p.run_seed);
      flatten(s["timings"], "timings.", row.numbers);
      flatten(s["metrics"], "metrics.", row.numbers);
      if (s["metrics"].contains("units") && s["metrics"]["units"].is_string())
        row.units = s["metrics"]["units"].get<std::string>();
    }
    for (const auto& [k, v] : row.numbers)
      if (seen.insert(k).second) t.columns.push_back(k);
    t.rows.push_back(std::move(row));
  }
  // timings first, then metrics, each sorted: the same columns in the same order every time.
  std::sort(t.columns.begin(), t.columns.end());
  return t;
}

void write_table(const SweepSpec& spec, const SweepTable& table, const fs::path& dir) {
  const fs::path file = dir / "sweep.csv", tmp = dir / ".sweep.csv.tmp";
  {
    std::ofstream out(tmp);
    out << "point,repeat,seed";
    for (const auto& a : spec.axes) out << "," << csv_field(a.key);
    out << ",status,exit_code,error,run_wall_s";
    for (const auto& c : table.columns) out << "," << csv_field(c);
    out << "\n";
    for (const auto& r : table.rows) {
      const bool ok = r.status.state == PointStatus::State::Done;
      out << r.point->index << "," << r.point->repeat << "," << r.seed;
      for (const auto& [k, v] : r.point->values) out << "," << csv_field(v);
      out << "," << (ok ? "ok" : "failed") << "," << r.status.exit_code << ","
          << csv_field(r.status.error) << "," << number(r.status.wall_s);
      for (const auto& c : table.columns) {
        const auto v = table.value(r, c);
        out << "," << (v ? number(*v) : "");
      }
      out << "\n";
    }
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, file);
}

}  // namespace conform::scenes
