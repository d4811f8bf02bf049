// The growth of a body's tear by Griffith's criterion (tear_growth.hpp in the public headers
// says what it promises). It owns the tips it grows: taken from the tear's two ends whenever the
// blade has lengthened the tear since, then moved by each extension. It works through the body's
// public edits (apply), so Bullet mirrors every growth step as it mirrors any change.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <utility>
#include <vector>

#include "conform/bullet/tear_growth.hpp"
#include "conform/membrane/energy_release.hpp"
#include "conform/mesh/skinned_mesh.hpp"

namespace conform::mesh {
class Tear;
}

namespace conform::bullet {

class SkinnedSoftBody;

class TearGrowth {
 public:
  /// The skin's rest state per vertex, read at each use (the bind pose: it grows with the mesh).
  using RestSource = std::function<Eigen::Ref<const Eigen::Matrix3Xd>()>;
  explicit TearGrowth(RestSource skin_rest) : skin_rest_(std::move(skin_rest)) {}
  /// Forgets the tips and the length grown (a new tear).
  void reset() {
    tips_.clear();
    tear_ = nullptr;
    tear_points_ = -1;
    grown_ = 0;
  }
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
                  std::size_t i);
  void extend(SkinnedSoftBody& body, mesh::Tear& tear, std::size_t i, TipGrowth& judged);

  // The body's mesh with the skin's rest state as its rest points: the body's own mesh when they
  // are the same, else view_, copied once per grow() (take_view) and kept in step with the body
  // by applying each growth step's change to it too (the bind pose grows by the same rule).
  const mesh::SkinnedMesh& skin_mesh(const SkinnedSoftBody& body) const;
  void take_view(const SkinnedSoftBody& body);

  RestSource skin_rest_;
  mesh::SkinnedMesh view_;
  bool own_view_ = false;  // skin_mesh() is view_ (the skin's rest is not the mesh's points)
  std::vector<Tip> tips_;
  const mesh::Tear* tear_ = nullptr;
  std::int32_t tear_points_ = -1;  // the blade's path when the tips were taken
  double grown_ = 0;
};

}  // namespace conform::bullet
