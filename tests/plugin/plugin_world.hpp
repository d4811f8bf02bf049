// A real Bullet soft-rigid world for the plugin tests (no gravity unless asked).
#pragma once

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include "conform/bullet/skinned_soft_body.hpp"
#include "conform/bullet/soft_world.hpp"
#include "conform/mesh/primitives.hpp"
#include "conform/skin/pose.hpp"

namespace conform::test {

/// The plugin's soft world with the tests' defaults: gravity g along −z (none unless asked),
/// and steps of one 1/60 s substep.
struct SoftWorld : bullet::SoftWorld {
  explicit SoftWorld(double gravity = 0) : bullet::SoftWorld(btVector3(0, 0, btScalar(-gravity))) {}
  void step(int n = 1, double dt = 1.0 / 60) {
    for (int i = 0; i < n; ++i) bullet::SoftWorld::step(dt);
  }
};

/// A flat sheet (see mesh::make_sheet) skinned wholly to bone 0: it rides the identity pose.
inline mesh::SkinnedMesh one_bone_sheet(int cells_x, int cells_y, double width, double height) {
  mesh::SkinnedMesh m = mesh::make_sheet(cells_x, cells_y, width, height);
  m.bones.setZero();
  m.weights.setZero();
  m.weights.row(0).setOnes();
  return m;
}

/// A skeleton of one bone at the origin, for one_bone_sheet.
inline skin::Skeleton one_bone_skeleton() {
  skin::Skeleton s;
  s.joints.push_back({"root", -1, skin::Versor::identity()});
  s.bones.push_back({"root", 0, skin::Versor::identity()});
  return s;
}

/// The arm's rest pose with the shoulder turned about y and the elbow bent about x (radians).
inline skin::Pose bent_arm_pose(const skin::Skeleton& skeleton, double shoulder, double elbow) {
  skin::Pose pose = skin::Pose::rest(skeleton);
  const auto turn = [](double angle, const Eigen::Vector3d& axis) {
    return skin::Versor::from_trs(cga::Vec3<double>::Zero(),
                                  cga::Quat<double>(Eigen::AngleAxisd(angle, axis)), 1.0);
  };
  pose.apply_local(0, turn(shoulder, Eigen::Vector3d::UnitY()));
  pose.apply_local(1, turn(elbow, Eigen::Vector3d::UnitX()));
  return pose;
}

/// Bending links of a skinned body against its mesh, counted independently of the plugin's
/// own bookkeeping: a correct link joins the two vertices opposite an edge that exactly two
/// faces of the mesh use; `expected` counts such edges (with distinct opposite vertices).
struct BendingCheck {
  int links = 0;     // Bullet links of material 1 over all pieces
  int wrong = 0;     // of which no edge of the mesh explains
  int expected = 0;  // edges shared by exactly two faces
};

inline BendingCheck check_bending(const bullet::SkinnedSoftBody& body) {
  const auto& m = body.mesh();
  std::map<std::pair<std::int32_t, std::int32_t>, std::vector<std::int32_t>> opposite;
  for (const auto& f : m.faces)
    for (int k = 0; k < 3; ++k)
      opposite[std::minmax(f[std::size_t(k)], f[std::size_t((k + 1) % 3)])].push_back(
          f[std::size_t((k + 2) % 3)]);
  std::map<std::pair<std::int32_t, std::int32_t>, int> pairs;  // opposite pair → edges
  BendingCheck out;
  for (const auto& [edge, far] : opposite)
    if (far.size() == 2 && far[0] != far[1]) {
      ++out.expected;
      ++pairs[std::minmax(far[0], far[1])];
    }
  for (btSoftBody* sb : body.pieces())
    for (int i = 0; i < sb->m_links.size(); ++i) {
      const auto& l = sb->m_links[i];
      if (l.m_material == sb->m_materials[0]) continue;
      ++out.links;
      const std::int32_t c = body.vertex_of(sb, int(l.m_n[0] - &sb->m_nodes[0])),
                         d = body.vertex_of(sb, int(l.m_n[1] - &sb->m_nodes[0]));
      auto it = pairs.find(std::minmax(c, d));
      if (it == pairs.end() || it->second == 0)
        ++out.wrong;
      else
        --it->second;
    }
  return out;
}

/// Bullet's own invariants in every piece, which its per-step code relies on without checks:
/// each node has a leaf of the body's node tree (m_ndbvt) pointing back at it, the tree holds
/// exactly those leaves and every internal volume contains its children's; faces and links
/// point at nodes and materials of their own body; link constants match the rest lengths and
/// masses (c0 = (1/m_a + 1/m_b) / kLST, c1 = rl²); and no edit asked Bullet for its whole-body
/// reset (m_bUpdateRtCst), which would wipe the plugin's rest lengths. Returns the first
/// violation found, or an empty string.
inline std::string bullet_internals_problem(const bullet::SkinnedSoftBody& body) {
  for (btSoftBody* sb : body.pieces()) {
    const int n = sb->m_nodes.size();
    const btSoftBody::Node* first = n ? &sb->m_nodes[0] : nullptr;
    auto own_node = [&](const btSoftBody::Node* p) { return n && p >= first && p < first + n; };
    auto own_material = [&](const btSoftBody::Material* m) {
      for (int i = 0; i < sb->m_materials.size(); ++i)
        if (sb->m_materials[i] == m) return true;
      return false;
    };
    if (sb->m_bUpdateRtCst) return "a body awaits Bullet's whole-body reset";
    if (sb->m_ndbvt.m_leaves != n) return "node tree leaf count != node count";
    if ((sb->m_ndbvt.m_root == nullptr) != (n == 0)) return "node tree root vs node count";
    for (int i = 0; i < n; ++i) {
      const btSoftBody::Node& node = sb->m_nodes[i];
      if (!node.m_leaf || !node.m_leaf->isleaf() || node.m_leaf->data != &node)
        return "node without its own tree leaf";
      const btDbvtNode* up = node.m_leaf;
      while (up->parent) up = up->parent;
      if (up != sb->m_ndbvt.m_root) return "node leaf outside its body's tree";
      if (!own_material(node.m_material)) return "node material of another body";
    }
    if (sb->m_ndbvt.m_root) {
      int leaves = 0;
      std::vector<const btDbvtNode*> stack{sb->m_ndbvt.m_root};
      while (!stack.empty()) {
        const btDbvtNode* t = stack.back();
        stack.pop_back();
        if (t->isleaf()) {
          ++leaves;
          continue;
        }
        for (const btDbvtNode* c : t->childs) {
          if (c->parent != t) return "node tree child with another parent";
          if (!t->volume.Contain(c->volume)) return "node tree volume misses a child";
          stack.push_back(c);
        }
      }
      if (leaves != n) return "node tree reaches a different number of leaves";
    }
    for (int i = 0; i < sb->m_faces.size(); ++i) {
      const auto& f = sb->m_faces[i];
      for (const auto* p : f.m_n)
        if (!own_node(p)) return "face node outside its body";
      if (!own_material(f.m_material)) return "face material of another body";
    }
    for (int i = 0; i < sb->m_links.size(); ++i) {
      const auto& l = sb->m_links[i];
      if (!own_node(l.m_n[0]) || !own_node(l.m_n[1])) return "link node outside its body";
      if (!own_material(l.m_material)) return "link material of another body";
      const double c0 = double(l.m_n[0]->m_im + l.m_n[1]->m_im) / double(l.m_material->m_kLST);
      if (std::abs(double(l.m_c0) - c0) > 1e-5 * (1 + c0)) return "link c0 off its masses";
      const double c1 = double(l.m_rl) * double(l.m_rl);
      if (std::abs(double(l.m_c1) - c1) > 1e-5 * (1e-12 + c1)) return "link c1 != rl²";
    }
  }
  return {};
}

}  // namespace conform::test
