// The side-by-side picture of one frame, composed in-process with cairo: the panels f3d rendered,
// left to right under their names, a title above them, and on the right the colour bar with its
// values and the wound bed's swatch.
//
// Why cairo and not a script: composing with gnuplot cost 0.34-0.46 s per picture (its start-up
// and PNG decoding), as much as the f3d renders themselves; here it is a few tens of ms.
#pragma once

#include <filesystem>
#include <string>
#include <vector>

#include "render/colour_scale.hpp"

namespace conform::scenes {

/// The picture's size for `panels` panels of `width` x `height` pixels (margins included).
struct PictureSize {
  int width, height;
};
PictureSize picture_size(int panels, int width, int height);

/// Writes the picture of one frame to `out` (PNG) from `renders`, pasted left to right: the
/// renders of its panels (each `width` x `height`), one strip of all or one per panel, with
/// `names[k]` above panel k. Throws std::runtime_error naming the file that could not be read
/// or written; `out` is then not written.
void compose_picture(const std::filesystem::path& out,
                     const std::vector<std::filesystem::path>& renders,
                     const std::vector<std::string>& names, int width, int height,
                     const std::string& title, const ColourScale& scale);

}  // namespace conform::scenes
