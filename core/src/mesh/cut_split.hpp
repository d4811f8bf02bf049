// Step 3 of the planar cut (cut.hpp): a new vertex per crossed edge, and every face the cut
// touches made pending faces with a side. Internal to core.
#pragma once

#include "cut_sections.hpp"

namespace conform::mesh::cutting {

class CutSplit : public CutSections {
 public:
  using CutSections::CutSections;

 protected:
  // Step 3's vertex on crossed edge (u, w), made once for the faces on both sides.
  std::int32_t cross_vertex(std::int32_t u, std::int32_t w);
  Eigen::Vector3d pos(std::int32_t v) const {
    return v < nv0_ ? Eigen::Vector3d(mesh_.current.col(v))
                    : sc_.xpos[static_cast<std::size_t>(v - nv0_)];
  }
  // Step 3: one new vertex per crossed edge; every work face becomes pending faces with a
  // side (split faces in pieces, faces touching the plane re-indexed later if a fan around
  // their plane vertices gets a copy). False when the plane only touches the mesh.
  bool split_crossed_faces();
  // A face on one side (or in the plane: the side opposite its normal) touching the plane:
  // pending, in case a fan around its plane vertex gets a copy.
  void keep_face(std::int32_t fi, const std::int8_t* s);
  // A crossed face split into triangles: two through a vertex on the plane, else the lone
  // vertex's triangle and its quad along the diagonal step 2 chose.
  void split_face(std::int32_t fi, const std::int8_t* s, std::size_t& next_crossed);
  // The change's faces: the pieces of split faces and the re-indexed faces in, their
  // originals out.
  void emit_faces();

  std::vector<std::int32_t> split_;  // the crossed faces, then the re-indexed ones: removed
};

}  // namespace conform::mesh::cutting
