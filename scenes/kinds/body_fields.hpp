// The per-vertex fields of a skinned soft body's kept frame, for the ParaView series
// (render/vtk_series.hpp): what the PLY frame holds (every vertex, the faces with their tags) and
// per vertex the displacement from the bind pose, the
// velocity, the edge stretch, the gap across the lips (where the scene has lips), the membrane's
// principal stresses (where the body uses the membrane) and the piece.
#pragma once

#include "conform/bullet/skinned_soft_body.hpp"
#include "render/frame_snapshot.hpp"
#include "render/vertex_fields.hpp"

namespace conform::scenes {

/// The fields of `body` as of its last sync_mesh(). `lips` null: the scene has no wound, and
/// the gap is left out (an empty Lips is a wound not yet made: a gap of 0).
VertexFields body_fields(const bullet::SkinnedSoftBody& body, const Lips* lips);

}  // namespace conform::scenes
