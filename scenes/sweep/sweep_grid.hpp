// The points of a sweep: --grid axes combined as a Cartesian product, --zip axes advanced
// together (one combined axis), each point repeated with seeds 1..N when --repeat N > 1.
// Values stay text: they become `--set KEY=VALUE` of the point's `conform run`, so they are
// read exactly as --set reads them (JSON when it parses, a string otherwise).
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "base/scene_config.hpp"

namespace conform::scenes {

struct SweepAxis {
  std::string key;                  // dotted scene key, e.g. physics.substeps
  std::vector<std::string> values;  // in the order given
  bool zipped = false;              // --zip: advances with the other zipped axes
};

struct SweepPoint {
  int index = 0;                                            // 0-based, the --task number
  std::vector<std::pair<std::string, std::string>> values;  // one per axis, in axis order
  int repeat = 0;                                           // 0 .. repeat-1
  std::uint64_t seed = 0;      // set with --set seed=... when repeating (0: the scene's own)
  std::uint64_t run_seed = 0;  // the seed the run uses (known once the point is validated)

  /// The `--set` assignments of this point (its values, then the seed when repeating).
  std::vector<std::string> assignments() const;
  /// "k=v, k=v (seed s)" for messages and plot legends.
  std::string label() const;
};

/// Splits "KEY=V1,V2,..." into an axis. Commas inside [..], {..} or "..." do not split, so
/// JSON arrays are values. Throws SceneError naming the option and the text.
SweepAxis parse_axis(const std::string& option, const std::string& spec, bool zipped);

/// The points: the product of the grid axes (the last one varying fastest) with the zipped
/// axes as one more axis, each repeated `repeat` times. Throws SceneError for a key given
/// twice, zipped axes of different lengths, or seed swept while repeating.
std::vector<SweepPoint> expand(const std::vector<SweepAxis>& axes, int repeat);

/// The most points one sweep may have (a Slurm array and the folder names stay reasonable).
inline constexpr int kMaxSweepPoints = 100000;

}  // namespace conform::scenes
