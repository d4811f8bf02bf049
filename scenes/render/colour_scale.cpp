#include "render/colour_scale.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace conform::scenes {

Rgb ColourScale::operator()(double value) const {
  if (!std::isfinite(value)) return {0.5, 0.5, 0.5};
  const double u = max > min ? std::clamp((value - min) / (max - min), 0.0, 1.0) : 0.5;
  for (std::size_t i = 1; i < stops.size(); ++i)
    if (u <= stops[i][0] || i + 1 == stops.size()) {
      const auto& a = stops[i - 1];
      const auto& b = stops[i];
      const double w = b[0] > a[0] ? std::clamp((u - a[0]) / (b[0] - a[0]), 0.0, 1.0) : 0.0;
      return {a[1] + w * (b[1] - a[1]), a[2] + w * (b[2] - a[2]), a[3] + w * (b[3] - a[3])};
    }
  return {stops.back()[1], stops.back()[2], stops.back()[3]};
}

ColourScale make_scale(const std::string& scalar, std::span<const double> values, double range) {
  ColourScale s;
  // A high percentile rather than the largest value: a few stretched slivers at a blade's tip
  // would otherwise wash every other vertex into the middle colour.
  std::vector<double> mags;
  mags.reserve(values.size());
  for (const double v : values)
    if (std::isfinite(v) && v != 0) mags.push_back(std::abs(v));
  double top = range;
  if (!(top > 0) && !mags.empty()) {
    const auto k = static_cast<std::size_t>(0.98 * double(mags.size() - 1));
    std::nth_element(mags.begin(), mags.begin() + static_cast<std::ptrdiff_t>(k), mags.end());
    top = mags[k];
  }
  if (!(top > 0)) top = scalar == "gap" ? 1e-3 : 0.01;
  const std::array<double, 4> skin{0.5, 1.0, 0.86, 0.72};
  if (scalar == "gap") {
    s.label = "gap width across the lips [m]";
    s.min = 0, s.max = top;
    s.stops = {{0, 1.0, 0.86, 0.72}, {0.5, 0.30, 0.70, 0.75}, {1, 0.10, 0.15, 0.55}};
  } else {
    s.label = "stretch: mean edge strain [-]";
    s.min = -top, s.max = top;
    s.stops = {{0, 0.15, 0.30, 0.80}, skin, {1, 0.95, 0.55, 0.05}};
  }
  return s;
}

}  // namespace conform::scenes
