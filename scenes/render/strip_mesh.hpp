// The render input of one frame: every panel's coloured surface and its wound bed, moved to
// its place in the strip (strip_camera) and clipped to its own column of the picture, so that
// a limb longer than a panel is wide does not reach into its neighbour's.
//
// The wound bed: each surface is drawn twice, as it is and as an inner layer moved a skin's
// thickness inwards with its faces turned (so that it faces the inside) in the wound bed's
// colour. From outside the skin hides it; through an open wound it is what one sees, instead
// of the far inner wall of a hollow limb.
#pragma once

#include <string>
#include <vector>

#include "render/colour_scale.hpp"
#include "render/event_camera.hpp"
#include "render/frame_snapshot.hpp"

namespace conform::scenes {

/// `frame`'s panels, left to right, as one binary little-endian PLY with per-vertex colours
/// (f3d reads them as its "RGB" array), in the view frame of strip.camera (view_frame: seen
/// through view_frame_camera, it gives strip.camera's picture); `aspect` is one panel's
/// width / height.
std::string strip_ply(const std::vector<FrameSnapshot>& frame, const ColourScale& scale,
                      const StripCamera& strip, double aspect);

}  // namespace conform::scenes
