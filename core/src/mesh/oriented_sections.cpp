#include "oriented_sections.hpp"

#include <algorithm>
#include <numeric>

namespace conform::mesh::detail {

namespace {

double signed_area(const std::vector<Eigen::Vector2d>& loop) {
  double twice = 0;
  for (std::size_t i = 0, j = loop.size() - 1; i < loop.size(); j = i++)
    twice += loop[j].x() * loop[i].y() - loop[i].x() * loop[j].y();
  return twice / 2;
}

// The loops `group` (indices into `loops`) as a section of their own: their triangulation,
// with the forbidden diagonals between their vertices, in the concatenation of `group`.
struct GroupSection {
  const std::vector<std::vector<Eigen::Vector2d>>& loops;
  const std::vector<std::int32_t>& offset;  // first index of each loop in the concatenation
  SectionTriangulator method;
  const ForbiddenDiagonals& forbidden;

  SectionTriangulation triangulate(const std::vector<std::size_t>& group,
                                   std::vector<std::int32_t>& global) const {
    std::vector<std::vector<Eigen::Vector2d>> subset;
    std::vector<std::int32_t> local(std::size_t(offset.back()), -1);
    global.clear();
    for (const std::size_t l : group) {
      subset.push_back(loops[l]);
      for (std::int32_t i = offset[l]; i < offset[l + 1]; ++i) {
        local[std::size_t(i)] = std::int32_t(global.size());
        global.push_back(i);
      }
    }
    ForbiddenDiagonals kept;
    for (const auto& [a, b] : forbidden)
      if (local[std::size_t(a)] >= 0 && local[std::size_t(b)] >= 0)
        kept.push_back({local[std::size_t(a)], local[std::size_t(b)]});
    return triangulate_section(subset, method, kept);
  }
};

// Whether `section`'s triangles (in the concatenation `global` of the loops, each running from
// offset[l] to offset[l + 1]) run the loops' edges the other way more often than their way.
// The loops' order comes from the surface's faces, so this is the surface's own orientation:
// it decides where the signed areas cannot (a loop far from the origin, or folded on itself,
// whose area's sign is lost to rounding).
bool runs_against_loops(const SectionTriangulation& section,
                        const std::vector<std::int32_t>& global,
                        const std::vector<std::int32_t>& offset) {
  const auto next = [&](std::int32_t i) {
    const auto l =
        std::size_t(std::upper_bound(offset.begin(), offset.end(), i) - offset.begin() - 1);
    return i + 1 == offset[l + 1] ? offset[l] : i + 1;
  };
  long with = 0, against = 0;
  for (const auto& t : section.triangles)
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = global[std::size_t(t[k])], b = global[std::size_t(t[(k + 1) % 3])];
      with += next(a) == b;
      against += next(b) == a;
    }
  return against > with;
}

}  // namespace

OrientedSections oriented_sections(const std::vector<std::vector<Eigen::Vector2d>>& loops,
                                   SectionTriangulator method,
                                   const ForbiddenDiagonals& forbidden) {
  std::vector<std::int32_t> offset(loops.size() + 1, 0);
  std::vector<bool> counter_clockwise(loops.size());
  for (std::size_t l = 0; l < loops.size(); ++l) {
    offset[l + 1] = offset[l] + std::int32_t(loops[l].size());
    counter_clockwise[l] = signed_area(loops[l]) > 0;
  }
  const GroupSection sections{loops, offset, method, forbidden};
  OrientedSections out;
  std::vector<std::size_t> pending(loops.size());
  std::iota(pending.begin(), pending.end(), std::size_t(0));
  std::vector<std::int32_t> global;
  // Each round caps a group: of the loops left, those that run as their nesting in the group
  // says (outer counter-clockwise, holes clockwise), or, when none does, those that all run
  // the other way (an inside-out surface: the group's triangles are reversed). The rest wait
  // for a later round. The group never empties and the rest shrinks, so this ends.
  while (!pending.empty()) {
    std::vector<std::size_t> group = pending, deferred;
    SectionTriangulation section;
    bool inside_out = false;
    while (true) {
      section = sections.triangulate(group, global);
      if (!section.ok()) {
        OrientedSections failed;
        failed.problem = section.problem;
        return failed;
      }
      std::vector<std::size_t> as_nested, reversed;
      for (std::size_t k = 0; k < group.size(); ++k)
        (counter_clockwise[group[k]] == (section.depth[k] % 2 == 0) ? as_nested : reversed)
            .push_back(group[k]);
      if (as_nested.size() == group.size() || reversed.size() == group.size()) {
        inside_out = runs_against_loops(section, global, offset);
        break;
      }
      // Both kinds (pieces overlapping in the plane): the reversed ones wait, and nest anew
      // among themselves in a later round.
      deferred.insert(deferred.end(), reversed.begin(), reversed.end());
      group = std::move(as_nested);
    }
    for (const auto& t : section.triangles) {
      const std::int32_t a = global[std::size_t(t[0])], b = global[std::size_t(t[1])],
                         c = global[std::size_t(t[2])];
      out.triangles.push_back(inside_out ? std::array{a, c, b} : std::array{a, b, c});
    }
    out.capped_loops += std::int32_t(group.size());
    out.inside_out_loops += inside_out ? std::int32_t(group.size()) : 0;
    for (const auto d : section.depth) out.nested_loops += d > 0;
    pending = std::move(deferred);
  }
  return out;
}

}  // namespace conform::mesh::detail
