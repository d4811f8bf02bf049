#include "conform/io/weld_model.hpp"

#include <algorithm>
#include <string>

namespace conform::io {

namespace {

// The welded model's influence lists: each kept vertex's own, or for a vertex welded with its
// copies' mean weights (mesh/weld.hpp) the mean of their lists, bone by bone.
skin::InfluenceLists keep_influences(const skin::InfluenceLists& in,
                                     const mesh::WeldResult& result) {
  // Each new vertex's copies (the old vertices welded into it): its own alone, unless averaged.
  std::vector<std::vector<std::int32_t>> copies(result.kept.size());
  for (std::size_t n = 0; n < result.kept.size(); ++n) copies[n] = {result.kept[n]};
  for (const std::int32_t a : result.averaged) copies[std::size_t(a)].clear();
  for (std::size_t v = 0; v < result.vertex_map.size(); ++v) {
    const auto n = std::size_t(result.vertex_map[v]);
    if (std::binary_search(result.averaged.begin(), result.averaged.end(), std::int32_t(n)))
      copies[n].push_back(std::int32_t(v));
  }
  skin::InfluenceLists out;
  out.offsets.assign(1, 0);
  for (const std::vector<std::int32_t>& from : copies) {
    const auto first = std::ptrdiff_t(out.bones.size());
    const double share = 1.0 / double(from.size());
    for (const std::int32_t v : from)
      for (auto i = in.offsets[std::size_t(v)]; i < in.offsets[std::size_t(v) + 1]; ++i) {
        const std::int32_t bone = in.bones[std::size_t(i)];
        const double w = in.weights[std::size_t(i)];
        const auto at = from.size() == 1  // a kept vertex's own list, as it is
                            ? out.bones.end()
                            : std::find(out.bones.begin() + first, out.bones.end(), bone);
        if (at == out.bones.end()) {
          out.bones.push_back(bone);
          out.weights.push_back(from.size() == 1 ? w : w * share);
        } else {
          out.weights[std::size_t(at - out.bones.begin())] += w * share;
        }
      }
    out.offsets.push_back(std::int32_t(out.bones.size()));
  }
  return out;
}

// A range [first, first + count) of old indices, in the new numbering (`map` is monotone on
// what it keeps; −1 entries are dropped faces).
void renumber_range(std::int32_t& first, std::int32_t& count, const std::vector<std::int32_t>& map,
                    bool vertices) {
  std::int32_t new_first = -1, kept = 0, last = -1;
  for (std::int32_t i = first; i < first + count; ++i) {
    const std::int32_t m = map[std::size_t(i)];
    if (m < 0 || (vertices && m <= last)) continue;  // a dropped face, or a welded vertex
    if (new_first < 0) new_first = m;
    last = m;
    ++kept;
  }
  if (new_first < 0) {  // nothing left: an empty range where the next one starts
    new_first = 0;
    for (std::int32_t i = first - 1; i >= 0; --i)
      if (map[std::size_t(i)] >= 0) {
        new_first = map[std::size_t(i)] + 1;
        break;
      }
  }
  first = new_first;
  count = kept;
}

}  // namespace

mesh::WeldResult weld_model(SkinnedModel& model, const mesh::WeldOptions& options) {
  std::vector<std::int32_t> group(std::size_t(model.mesh.vertex_count()), -1);
  for (std::size_t m = 0; m < model.meshes.size(); ++m)
    for (std::int32_t v = model.meshes[m].first_vertex;
         v < model.meshes[m].first_vertex + model.meshes[m].vertex_count; ++v)
      group[std::size_t(v)] = std::int32_t(m);
  const bool lists = model.influences.vertex_count() == model.mesh.vertex_count();
  mesh::WeldResult result = mesh::weld(model.mesh, options, group);
  if (lists) model.influences = keep_influences(model.influences, result);
  for (auto& info : model.meshes) {
    renumber_range(info.first_vertex, info.vertex_count, result.vertex_map, true);
    renumber_range(info.first_face, info.face_count, result.face_map, false);
  }
  if (result.kept_apart > 0)
    model.warnings.push_back(std::to_string(result.kept_apart) +
                             " vertices at a welded position kept apart: their bone weights "
                             "differ by more than " +
                             std::to_string(options.weight_tolerance));
  if (!result.averaged.empty())
    model.warnings.push_back(
        std::to_string(result.averaged.size()) +
        " welded positions joined copies whose bone weights differ (by up to " +
        std::to_string(result.largest_weight_difference) +
        "): each takes its copies' mean weights, so the seam stays closed "
        "(WeldOptions::differing_weights = keep_apart keeps them apart, as in the file)");
  if (result.collapsed_faces > 0)
    model.warnings.push_back("welding collapsed " + std::to_string(result.collapsed_faces) +
                             " faces to a line or point; dropped");
  return result;
}

}  // namespace conform::io
