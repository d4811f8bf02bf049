// The topology mirror: one mesh::TopologyChange, already applied to the mesh, applied to the
// Bullet bodies in named phases (topology_mirror.cpp) that share one MirrorContext: the change
// (input), what the phases hand each other (state), and where the results go (the books and
// ApplyStats, output).
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <tuple>
#include <utility>
#include <vector>

#include "conform/bullet/skinned_soft_body.hpp"
#include "conform/mesh/topology_change.hpp"

namespace conform::bullet {

struct MirrorContext {
  // --- Input ---
  const mesh::TopologyChange& change;
  std::int32_t v0;     // vertices before the change (the new ones are v0, v0 + 1, …)
  std::int32_t added;  // new vertices
  std::size_t total;   // vertices after the change
  bool bending;        // bending links are made
  // --- State ---
  std::vector<Eigen::Vector3d> x, v;  // per new vertex: position and velocity
  std::vector<std::int32_t> touched;  // old vertices whose mass changed
  std::vector<std::int32_t> pending;  // mesh faces to add to Bullet
  // Per pending face, a bit per edge that no face used until now: only such an edge lacks a
  // link (an edge that kept a face kept its link).
  std::vector<std::uint8_t> new_edges;
  // Per complete piece of the split search: the body it joins (−1: a new one).
  std::vector<std::int32_t> owner;
  std::int32_t open_body = -1;            // the body the search left unexplored (keeps its nodes)
  std::vector<std::int32_t> moved_faces;  // left their body, to be re-added (same slots)
  std::vector<std::tuple<std::int32_t, std::int32_t, double>> moved_links;  // (a, b, rest)
  // --- Output: the books of SkinnedSoftBody::Impl; phase times here ---
  ApplyStats::Seconds& seconds;
  double clock;

  MirrorContext(const mesh::TopologyChange& c, std::int32_t base, bool bend,
                ApplyStats::Seconds& sec, double now)
      : change(c),
        v0(base),
        added(std::int32_t(c.new_vertices.size())),
        total(std::size_t(base) + c.new_vertices.size()),
        bending(bend),
        x(c.new_vertices.size()),
        v(c.new_vertices.size()),
        seconds(sec),
        clock(now) {}
};

}  // namespace conform::bullet
