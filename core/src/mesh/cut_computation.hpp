// One planar cut (Algorithm 1, steps 1–5 of cut.hpp) over the per-thread scratch arrays: the
// steps in order, each from its layer (cut_classify.hpp). Internal to core.
#pragma once

#include "cut_caps.hpp"

namespace conform::mesh::cutting {

class CutComputation : public CutCaps {
 public:
  using CutCaps::CutCaps;
  CutResult run();
};

}  // namespace conform::mesh::cutting
