// The planar cut's rounds without snapping where a snap pinched the section (cut.hpp).
#include <algorithm>

#include "cut_computation.hpp"

namespace conform::mesh::detail {

CutResult compute_cut(const SkinnedMesh& mesh, const cga::Plane<double>& plane,
                      const CutOptions& options, Predicates predicates) {
  // A vertex near a saddle of the surface, snapped onto the plane, can make the section meet
  // itself there (the surface touches the plane in two fans around it): that loop cannot be
  // capped. Such vertices are kept off the plane and the cut computed again, while that caps
  // more loops; each round bars at least one more vertex for good, so the rounds end.
  std::vector<std::int32_t>& barred = cutting::scratch().unsnappable;
  barred.clear();
  cutting::CutComputation first(mesh, plane, options, predicates);
  CutResult best = first.run();
  std::vector<std::int32_t> pinched = first.pinched_snaps();
  for (int round = 0; round < 8 && !pinched.empty() && best.capped_loops < best.loops; ++round) {
    const std::size_t before = barred.size();
    barred.insert(barred.end(), pinched.begin(), pinched.end());
    std::sort(barred.begin(), barred.end());
    barred.erase(std::unique(barred.begin(), barred.end()), barred.end());
    if (barred.size() == before) break;
    cutting::CutComputation again(mesh, plane, options, predicates);
    CutResult next = again.run();
    if (next.status != CutStatus::Cut || next.capped_loops <= best.capped_loops) break;
    next.unsnapped_vertices = std::int32_t(barred.size());
    best = std::move(next);
    pinched = again.pinched_snaps();
  }
  barred.clear();
  return best;
}

}  // namespace conform::mesh::detail
