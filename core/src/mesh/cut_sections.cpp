#include "cut_sections.hpp"

#include <algorithm>
#include <limits>
#include <numeric>

#include "conform/mesh/detail/union_find.hpp"

namespace conform::mesh::cutting {

bool CutSections::select_sections() {
  const CutRegion& region = options_.region;
  const std::int8_t* const sd = sc_.side.data();
  std::vector<std::int32_t>& parent = sc_.section_parent;
  parent.resize(static_cast<std::size_t>(nv0_));
  std::iota(parent.begin(), parent.end(), 0);
  for (const std::int32_t fi : sc_.work) {
    const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
    if (!in_section(f)) continue;
    detail::unite(parent.data(), f[0], f[1]);
    detail::unite(parent.data(), f[0], f[2]);
  }
  struct Section {
    std::int32_t points = 0, inside = 0;
    bool crossed = false;
    double nearest = std::numeric_limits<double>::infinity();  // squared, to region.center
  };
  std::vector<Section> sections;
  std::vector<std::int32_t>& section_of = sc_.section_of;  // by root vertex
  section_of.assign(static_cast<std::size_t>(nv0_), -1);
  auto measure = [&](Section& s, const Eigen::Vector3d& x) {
    ++s.points;
    s.inside += region.contains(x);
    s.nearest = std::min(s.nearest, (x - region.center).squaredNorm());
  };
  for (const std::int32_t fi : sc_.work) {
    const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
    if (!in_section(f)) continue;
    std::int32_t& id = section_of[static_cast<std::size_t>(detail::find_root(parent.data(), f[0]))];
    if (id < 0) id = static_cast<std::int32_t>(sections.size()), sections.emplace_back();
    Section& s = sections[static_cast<std::size_t>(id)];
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = f[k], w = f[(k + 1) % 3];
      if (sd[v] == 0) measure(s, point(v));
      if (sd[v] * sd[w] < 0) measure(s, crossing_point(v, w)), s.crossed = true;
    }
  }
  std::vector<std::uint8_t> kept(sections.size(), 0);
  std::size_t nearest = sections.size();
  for (std::size_t i = 0; i < sections.size(); ++i) {
    const Section& s = sections[i];
    if (!s.crossed) continue;
    ++result_.sections;
    if (region.shape == CutRegion::Shape::seed) {
      if (nearest == sections.size() || s.nearest < sections[nearest].nearest) nearest = i;
    } else {
      kept[i] = region.keep == CutRegion::Keep::inside ? s.inside == s.points : s.inside > 0;
    }
  }
  if (nearest < sections.size()) kept[nearest] = 1;
  for (std::size_t i = 0; i < sections.size(); ++i) result_.kept_sections += kept[i];
  std::erase_if(sc_.work, [&](std::int32_t fi) {
    const Face& f = mesh_.faces[static_cast<std::size_t>(fi)];
    if (!in_section(f)) return false;
    const std::int32_t root = detail::find_root(parent.data(), f[0]);
    return !kept[static_cast<std::size_t>(section_of[static_cast<std::size_t>(root)])];
  });
  return result_.kept_sections > 0;
}

}  // namespace conform::mesh::cutting
