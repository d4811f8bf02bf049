// The growth of a body's tear by Griffith's criterion (tear_growth.hpp in the public headers
// says what it promises). It owns the tips it grows: taken from the tear's two ends whenever the
// blade has lengthened the tear since, then moved by each extension. It works through the body's
// public edits (apply), so Bullet mirrors every growth step as it mirrors any change.
#pragma once

#include <cstdint>
#include <vector>

#include "conform/bullet/tear_growth.hpp"
#include "conform/membrane/energy_release.hpp"

namespace conform::mesh {
class Tear;
}

namespace conform::bullet {

class SkinnedSoftBody;

class TearGrowth {
 public:
  /// One growth step of `body`'s tear (SkinnedSoftBody::grow_tear); `tear` is that tear, which
  /// takes each grown segment (mesh::Tear::adopt_growth).
  TearGrowthReport grow(SkinnedSoftBody& body, mesh::Tear* tear);
  /// Rest-space length grown since the tear began, m.
  double grown() const { return grown_; }

 private:
  struct Tip {
    membrane::CrackTip crack;
    bool stopped = false;
  };
  // The tear's ends as tips, when the tear or its blade's steps changed since the last call.
  void follow_tear(const SkinnedSoftBody& body);
  TipGrowth judge(const SkinnedSoftBody& body, const std::vector<std::uint8_t>& fixed,
                  std::size_t i) const;
  void extend(SkinnedSoftBody& body, mesh::Tear& tear, std::size_t i, TipGrowth& judged);

  std::vector<Tip> tips_;
  const mesh::Tear* tear_ = nullptr;
  std::int32_t tear_points_ = -1;  // the blade's path when the tips were taken
  double grown_ = 0;
};

}  // namespace conform::bullet
