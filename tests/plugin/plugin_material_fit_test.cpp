// A body says what does not fit between its material and its mesh: link fields the membrane
// ignores, and an attachment whose decay length sqrt(E'' t / k) is below half an element.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "conform/bullet/plugin.hpp"
#include "plugin_world.hpp"

using namespace conform;
using conform::test::SoftWorld;

namespace {

std::vector<std::string> warnings(const mesh::SkinnedMesh& sheet, const bullet::Material& m) {
  SoftWorld w;
  bullet::Plugin plugin(w.world);
  return plugin.add_skinned_body(sheet, test::one_bone_skeleton(), m).material_warnings();
}

bool mentions(const std::vector<std::string>& all, const std::string& what) {
  for (const std::string& w : all)
    if (w.find(what) != std::string::npos) return true;
  return false;
}

// 2 cm cells: the skin's decay length, 4.6 cm at its defaults, spans two of them.
const mesh::SkinnedMesh kFine = test::one_bone_sheet(10, 10, 0.2, 0.2);

TEST(PluginMaterialFit, TheDefaultsFitAFineMesh) {
  EXPECT_TRUE(warnings(kFine, bullet::Material{}).empty());
}

TEST(PluginMaterialFit, LinkFieldsSetForTheMembraneAreNamed) {
  bullet::Material m;
  m.link_stiffness = 0.5;
  m.target_stiffness = 10;
  const auto w = warnings(kFine, m);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_TRUE(mentions(w, "link_stiffness, target_stiffness")) << w[0];
  m.model = bullet::MaterialModel::bullet_links;  // the links use them
  EXPECT_TRUE(warnings(kFine, m).empty());
}

TEST(PluginMaterialFit, AnAttachmentShorterThanHalfAnElementIsToldWithItsFigures) {
  const bullet::Material m;
  const double e2 = m.skin.youngs_modulus / (1 - 0.25);  // the neo-Hookean membrane: nu = 1/2
  const double decay = std::sqrt(e2 * m.skin.thickness / m.skin.attachment_stiffness);
  // Cells of 0.1 m: their median edge (0.1 m; the diagonals are longer) is over twice the decay.
  const auto w = warnings(test::one_bone_sheet(10, 10, 1.0, 1.0), m);
  ASSERT_EQ(w.size(), 1u);
  char figure[32];
  std::snprintf(figure, sizeof figure, "%.3g m", decay);
  EXPECT_TRUE(mentions(w, "skin.attachment_stiffness")) << w[0];
  EXPECT_TRUE(mentions(w, figure)) << w[0] << " (expected " << figure << ")";
  bullet::Material unattached;
  unattached.skin.attachment_stiffness = 0;
  unattached.skin.attachment_normal_stiffness = 0;
  EXPECT_FALSE(mentions(warnings(test::one_bone_sheet(10, 10, 1.0, 1.0), unattached), "decay"));
}

}  // namespace
