// The rest lengths kept through a change (kept_rest.hpp): the part's own rules, and on a live
// sagging sheet with pretension and bending links, cut twice: every link whose key edge and end
// vertices are the same before and after an edit has the same rest length (never one measured
// again on the moved nodes).
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <utility>
#include <vector>

#include "conform/bullet/plugin.hpp"
#include "kept_rest.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

using Edge = std::pair<std::int32_t, std::int32_t>;

// Per edge used by exactly two faces: its opposite vertices (min, max).
std::map<Edge, Edge> bending_ends(const mesh::SkinnedMesh& m) {
  std::map<Edge, std::vector<std::int32_t>> opposite;
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k)
      opposite[std::minmax(f[std::size_t(k)], f[std::size_t((k + 1) % 3)])].push_back(
          f[std::size_t((k + 2) % 3)]);
  std::map<Edge, Edge> out;
  for (const auto& [e, o] : opposite)
    if (o.size() == 2) out[e] = std::minmax(o[0], o[1]);
  return out;
}

}  // namespace

TEST(PluginKeptRest, KeepsPerKeyAndEndsAndClearsToEmpty) {
  bullet::KeptRest kept;
  kept.keep(1, 2, 1, 2, 0.5, false);
  kept.keep(1, 2, 0, 3, 0.7, true);
  EXPECT_EQ(kept.find(1, 2, 1, 2, false), 0.5);
  EXPECT_EQ(kept.find(1, 2, 0, 3, true), 0.7);
  EXPECT_EQ(kept.find(1, 2, 0, 4, true), -1);  // other ends: measured anew
  EXPECT_EQ(kept.find(2, 3, 2, 3, false), -1);
  kept.keep(1, 2, 1, 2, 0.6, false);  // the last kept for a key wins
  EXPECT_EQ(kept.find(1, 2, 1, 2, false), 0.6);
  kept.clear();
  EXPECT_TRUE(kept.empty());
  EXPECT_EQ(kept.find(1, 2, 1, 2, false), -1);
  EXPECT_EQ(kept.find(1, 2, 0, 3, true), -1);
}

TEST(PluginKeptRest, LinksWithTheSameKeyAndEndsKeepTheirRestThroughCuts) {
  SoftWorld w(9.81);
  bullet::Plugin plugin(w.world);
  bullet::Material material;
  material.model = bullet::MaterialModel::bullet_links;
  material.kinematic_weight = 2;
  material.target_stiffness = 0;
  material.target_damping = 0;
  material.pretension = 0.1;
  material.bending_stiffness = 0.5;
  const mesh::SkinnedMesh sheet = test::one_bone_sheet(12, 6, 1.2, 0.6);
  auto& body = plugin.add_skinned_body(sheet, test::one_bone_skeleton(), material);
  std::vector<std::int32_t> left;
  for (std::int32_t v = 0; v < sheet.vertex_count(); ++v)
    if (sheet.rest(0, v) < sheet.rest.row(0).minCoeff() + 1e-9) left.push_back(v);
  body.set_pinned(left);
  int compared = 0;
  for (const double x : {0.25, -0.15}) {
    w.step(3);  // sagging, links pulled short: a length measured again would differ
    const auto ends = bending_ends(body.mesh());
    std::map<Edge, double> rest, bend;
    for (const auto& [e, o] : ends) bend[e] = body.bending_rest_length(e.first, e.second);
    for (const auto& f : body.mesh().faces)
      for (int k = 0; k < 3; ++k) {
        const Edge e = std::minmax(f[std::size_t(k)], f[std::size_t((k + 1) % 3)]);
        rest[e] = body.rest_length(e.first, e.second);
      }
    ASSERT_EQ(body.cut(cga::Plane<double>::from_normal_point({1, 0, 0}, {x, 0, 0})).status,
              mesh::CutStatus::Cut);
    const auto after = bending_ends(body.mesh());
    for (const auto& [e, r] : rest) {
      const double now = body.rest_length(e.first, e.second);
      if (now < 0 || r < 0) continue;
      EXPECT_EQ(now, r) << e.first << " " << e.second;
      ++compared;
    }
    for (const auto& [e, o] : after) {
      const auto it = ends.find(e);
      if (it == ends.end() || it->second != o || bend[e] < 0) continue;
      const double now = body.bending_rest_length(e.first, e.second);
      if (now < 0) continue;
      EXPECT_EQ(now, bend[e]) << e.first << " " << e.second;
      ++compared;
    }
  }
  EXPECT_GT(compared, 100);
  EXPECT_EQ(body.piece_count(), 3);
}
