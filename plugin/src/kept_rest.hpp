// The rest lengths kept through one topology change: a link removed during the change whose
// link may come back (a face moved into another body, a bending link made again) gets its old
// rest length back instead of one measured on the moved nodes.
// Invariant: each kept entry is indexed by exactly one key, its key edge in the edge map or the
// bending map (the last entry kept for a key wins); a look-up matches the end vertices too;
// clear() empties the list and both maps (as between changes).
#pragma once

#include <cstddef>
#include <cstdint>
#include <tuple>
#include <vector>

#include "conform/mesh/edge_map.hpp"

namespace conform::bullet {

class KeptRest {
 public:
  /// Keeps `rest` for the link of key edge (a, b) joining (c, d): (c, d) = (a, b) for an edge
  /// link, the opposite vertices (min, max) for a bending link.
  void keep(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d, double rest,
            bool bending) {
    (bending ? bend_ : edge_).insert(a, b, std::int32_t(kept_.size()), true);
    kept_.emplace_back(a, b, c, d, rest);
  }
  /// The rest length kept for that link, or −1.
  double find(std::int32_t a, std::int32_t b, std::int32_t c, std::int32_t d, bool bending) const {
    const std::int32_t i = (bending ? bend_ : edge_).find(a, b);
    if (i < 0) return -1;
    const auto& [ka, kb, kc, kd, rest] = kept_[static_cast<std::size_t>(i)];
    return kc == c && kd == d ? rest : -1;
  }
  void clear() {
    for (std::size_t i = 0; i < kept_.size(); ++i) {
      const auto& [a, b, c, d, rest] = kept_[i];
      const bool bending = !(a == c && b == d);
      (bending ? bend_ : edge_).erase(a, b, std::int32_t(i));
    }
    kept_.clear();
  }
  std::size_t size() const { return kept_.size(); }
  bool empty() const { return kept_.empty() && edge_.size() == 0 && bend_.size() == 0; }

 private:
  // (a, b, c, d, rest): (a, b) the key edge, (c, d) the end vertices.
  std::vector<std::tuple<std::int32_t, std::int32_t, std::int32_t, std::int32_t, double>> kept_;
  mesh::EdgeMap edge_, bend_;  // key edge → index in kept_
};

}  // namespace conform::bullet
