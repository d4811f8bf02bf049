// The colour scale of the pictures and of the glTF's vertex colours: a piecewise-linear map
// from a scalar range to RGB, the same stops drawn as the pictures' colour bar, and the
// wound bed's colour (the inside of the skin), which no value of the scale takes.
#pragma once

#include <array>
#include <span>
#include <string>
#include <vector>

namespace conform::scenes {

using Rgb = std::array<double, 3>;  // each in [0, 1]

/// Dark crimson: what a viewer sees through an open wound (the inner layer of the skin).
inline constexpr Rgb kWoundBed{0.45, 0.04, 0.10};

struct ColourScale {
  std::string label;  // the colour bar's axis label, with the unit
  double min = 0, max = 1;
  std::vector<std::array<double, 4>> stops;  // (position in [0, 1], r, g, b), increasing

  Rgb operator()(double value) const;
};

/// The scale of a scalar ("stretch": diverging blue - skin - orange, symmetric about 0;
/// "gap": skin to deep blue from 0) over `values` (all frames' values, so that every picture
/// shares the scale). `range` > 0 fixes the range instead (stretch: ±range, gap: [0, range]).
ColourScale make_scale(const std::string& scalar, std::span<const double> values, double range);

}  // namespace conform::scenes
