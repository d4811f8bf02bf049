// The built-in procedural arm: upper arm, forearm and hand as one closed, consistently oriented
// (outward, counter-clockwise) tube with rounded caps, rigged to 3 bones.
//
// Dimensions follow the IK conventions: the shoulder is at the origin and the rest arm points
// along +z; the elbow is at z = 0.30 m, the wrist at z = 0.55 m and the finger tips at
// z = 0.63 m. The shoulder cap bulges a few centimetres behind the origin.
//
// The surface is `rings` rings of `segments` vertices each, plus one pole vertex at each end:
//   #V = rings · segments + 2,   #F = 2 · rings · segments   (closed genus 0: #F = 2 #V − 4).
// Resolution N scales both counts linearly (segments = 32 N, rings = 80 N), so
//   N = 1  →  2,562 vertices,   5,120 faces   (about the second paper's arm)
//   N = 14 →  ~502k vertices,   ~1.0M faces
//   N = 20 →  ~1.02M vertices,  ~2.05M faces.
// Vertex order: pole at the shoulder end (index 0), the rings from the shoulder to the hand
// (ring i, segment j at 1 + i·segments + j, j counter-clockwise seen from +z), then the pole at
// the finger tips (last index).
//
// Bones (the skeleton's joints and bones share indices): 0 shoulder (moves the upper arm),
// 1 elbow (forearm), 2 wrist (hand). Weights blend smoothly (smoothstep of z) across
// ±4 cm of the elbow and ±3 cm of the wrist; elsewhere a vertex follows one bone.
//
// A rigged model (mesh + skeleton), so it sits in the skin layer, above mesh, and its names are
// in conform::skin.
#pragma once

#include <cstdint>

#include "conform/mesh/skinned_mesh.hpp"
#include "conform/skin/skeleton.hpp"

namespace conform::skin {

struct ArmOptions {
  int resolution = 1;  // N: segments = 32 N around, rings = 80 N along
  int segments = 0;    // explicit counts override N when > 0 (segments ≥ 3, rings ≥ 2)
  int rings = 0;
  double upper_arm = 0.30;    // shoulder → elbow, m
  double forearm = 0.25;      // elbow → wrist, m
  double hand = 0.08;         // wrist → finger tips, m
  double elbow_blend = 0.04;  // half-width of the elbow's weight transition, m
  double wrist_blend = 0.03;  // half-width of the wrist's weight transition, m
};

struct Arm {
  mesh::SkinnedMesh mesh;  // rest == current, normals filled, uvs (around, along) in [0, 1]
  Skeleton skeleton;       // joints shoulder, elbow, wrist; bones 0, 1, 2 on them
};

/// Joint names of the arm's skeleton, in order.
inline constexpr const char* kArmJointNames[3] = {"shoulder", "elbow", "wrist"};

/// The largest resolution make_arm builds: N = 32 is 2,621,442 vertices. The surface grows as
/// N², and so does memory (docs/notes/import_skinning_ik.md).
inline constexpr int kMaxArmResolution = 32;
/// The most vertices make_arm builds (those of N = kMaxArmResolution), explicit counts too.
inline constexpr long long kMaxArmVertices = 80LL * kMaxArmResolution * 32 * kMaxArmResolution + 2;

/// Builds the arm. Throws std::invalid_argument for non-positive sizes or resolutions and for
/// more than kMaxArmResolution / kMaxArmVertices.
Arm make_arm(const ArmOptions& options = {});
/// Shorthand for make_arm({.resolution = resolution}).
Arm make_arm(int resolution);

}  // namespace conform::skin
