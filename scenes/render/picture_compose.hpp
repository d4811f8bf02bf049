// The side-by-side picture of one frame, composed in-process with cairo: the panels f3d rendered,
// left to right under their names with their captions below, a title above them, and on the
// right the colour bar with its values, the wound bed's swatch and a length scale.
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

/// A length scale for a picture: `metres_per_pixel` at the camera's target (the wound); 0 for
/// none. The bar drawn is the longest of 1, 2 or 5 times a power of ten that fits `max_pixels`.
struct ScaleBar {
  double metres_per_pixel = 0;
  double length_m = 0;  // chosen by scale_bar()
  int pixels = 0;
};
ScaleBar scale_bar(double metres_per_pixel, int max_pixels);
/// The longest scale bar the picture's right margin holds, pixels.
inline constexpr int kScaleBarPixels = 130;

/// What is written around the panels: the title, each panel's name above it and caption below
/// it (its headline number), the colour bar and the scale bar on the right.
struct PictureText {
  std::string title;
  std::vector<std::string> names, captions;
  ScaleBar bar;
};

/// Writes the picture of one frame to `out` (PNG) from `renders`, pasted left to right: the
/// renders of its panels (each `width` x `height`), one strip of all or one per panel, with
/// `text.names[k]` above panel k. Throws std::runtime_error naming the file that could not be
/// read or written; `out` is then not written.
void compose_picture(const std::filesystem::path& out,
                     const std::vector<std::filesystem::path>& renders, const PictureText& text,
                     int width, int height, const ColourScale& scale);

}  // namespace conform::scenes
