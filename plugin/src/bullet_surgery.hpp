// Bullet surgery: edits of a btSoftBody's arrays and node tree that Bullet itself has no call
// for (its append functions zero and copy, and ask for the whole-body reset; its tree insert
// walks from the root). The books-aware edits (add/remove node, face, link) are members of
// SkinnedSoftBody::Impl, in bullet_surgery.cpp.
#pragma once

#include <BulletSoftBody/btSoftBody.h>

#include <vector>

namespace conform::bullet {

/// Bullet's link constant c0 = (1/m_a + 1/m_b) / kLST (what its updateLinkConstants writes).
/// A material with kLST = 0 (the membrane's inert links) gets c0 = 0, which Bullet's link solve
/// skips.
inline void link_constant(btSoftBody::Link& l) {
  const btScalar k = l.m_material->m_kLST;
  l.m_c0 = k > 0 ? (l.m_n[0]->m_im + l.m_n[1]->m_im) / k : btScalar(0);
}

/// Bullet's face m_ra: twice the triangle's area (its AreaOf).
inline btScalar face_ra(const btSoftBody::Face& f) {
  return btCross(f.m_n[1]->m_x - f.m_n[0]->m_x, f.m_n[2]->m_x - f.m_n[0]->m_x).length();
}

/// Takes a leaf out of its tree without freeing anything: its parent (now redundant, its
/// other child takes its place) and the leaf itself go to `pool`, for the tree of another body.
/// Unlike btDbvt::remove, no ancestor is refitted here (see refit_tree).
void unlink_leaf(btDbvt& tree, btDbvtNode* leaf, std::vector<btDbvtNode*>& pool);

/// btDbvt::insert without its walk down from the root: the new leaf becomes the sibling of
/// `beside` (a leaf of the same tree, e.g. a neighbouring node's), and the ancestors grow as
/// btDbvt's own insert grows them.
btDbvtNode* insert_leaf_beside(btDbvt& tree, btDbvtNode* beside, const btDbvtVolume& volume,
                               void* data);

/// Recomputes every internal volume from its children (after many leaves were unlinked: one
/// pass over the tree instead of a refit walk per leaf).
void refit_tree(btDbvtNode* node);

/// Builds the node tree (m_ndbvt) of a body whose nodes have no leaves yet, in one pass: leaves
/// as appendNode makes them, joined in Morton order into a balanced tree. Tree nodes come from
/// `pool` (nodes unlinked from another tree) and then from btAlignedAlloc, as btDbvt's own (it
/// frees them); what the pool has left over is freed.
void build_node_tree(btSoftBody& body, std::vector<btDbvtNode*>& pool);

}  // namespace conform::bullet
