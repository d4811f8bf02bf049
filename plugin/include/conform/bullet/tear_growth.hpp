// A body's tear that grows by itself (SkinnedSoftBody::grow_tear): Griffith's criterion on the
// energy release rate G at each of the tear's two tips against the skin's toughness G_c
// (membrane::SkinMaterial::toughness), off by default (Material::growth).
//
// How, per call (between steps): G and the mode mix K_I, K_II at each tip come from the
// membrane's energy over a domain of a physical radius around it (a virtual crack extension,
// no element threshold), on the simulated positions brought into the rest frame by the best
// rigid fit of the skinned targets around the tip. Where G >= G_c the tip extends by one element
// of its fan in the direction of the maximum tangential stress (Erdogan-Sih), as one
// TopologyChange applied like any edit (mass and momentum kept). One extension per tip per call
// bounds the crack's speed by an element per step; the next step's dynamics re-equilibrate the
// skin before G is judged again. A tip that reaches the border or a pinned vertex stops.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace conform::bullet {

/// Material::growth. Lengths in metres (the world's unit is taken to be the metre).
struct TearGrowthSettings {
  bool enabled = false;
  /// R of the domain around each tip, > 0. It is further held below half the rest distance to
  /// the nearest kinematic vertex and to the other tip; keep it a few elements wide and below
  /// the attachment's decay length sqrt(E t / k) (the foundation's share of G is then small).
  double domain_radius = 0.006;
  /// The inner radius of the domain, as a fraction of R, in [0, 1).
  double inner_fraction = 0.25;
  /// Where the new tip lands on the fan's opposite edge: closer than this fraction of the edge
  /// to an end, the crack runs to that end instead (no sliver), in [0, 0.5).
  double snap_fraction = 0.15;
  /// Throws std::invalid_argument naming a field out of its range.
  void validate() const;
};

/// One tip's judgement in one grow_tear() call.
struct TipGrowth {
  std::int32_t vertex = -1;        // the tip before the call
  double energy_release_rate = 0;  // G, J/m^2
  double k1 = 0, k2 = 0;           // Pa m^1/2
  double domain_radius = 0;        // R used, m
  double kink = 0;                 // the growth direction relative to the crack's, rad
  double extended = 0;             // rest-space length grown in this call, m
  bool stopped = false;            // reached the border or a pinned vertex: no more growth
  std::string message;             // why a tip with G >= G_c did not grow (empty otherwise)
};

struct TearGrowthReport {
  std::vector<TipGrowth> tips;  // every running tip, judged on the state before any growth
  double grown = 0;             // this call's rest-space length, m
  double seconds = 0;           // CPU time of the call (thread), s
};

}  // namespace conform::bullet
