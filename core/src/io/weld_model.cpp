#include "conform/io/weld_model.hpp"

#include <string>

namespace conform::io {

namespace {

skin::InfluenceLists keep_influences(const skin::InfluenceLists& in,
                                     const std::vector<std::int32_t>& kept) {
  skin::InfluenceLists out;
  out.offsets.assign(1, 0);
  for (const std::int32_t v : kept) {
    for (auto i = in.offsets[std::size_t(v)]; i < in.offsets[std::size_t(v) + 1]; ++i) {
      out.bones.push_back(in.bones[std::size_t(i)]);
      out.weights.push_back(in.weights[std::size_t(i)]);
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
  if (lists) model.influences = keep_influences(model.influences, result.kept);
  for (auto& info : model.meshes) {
    renumber_range(info.first_vertex, info.vertex_count, result.vertex_map, true);
    renumber_range(info.first_face, info.face_count, result.face_map, false);
  }
  if (result.kept_apart > 0)
    model.warnings.push_back(std::to_string(result.kept_apart) +
                             " vertices at a welded position kept apart: their bone weights "
                             "differ by more than " +
                             std::to_string(options.weight_tolerance));
  if (result.collapsed_faces > 0)
    model.warnings.push_back("welding collapsed " + std::to_string(result.collapsed_faces) +
                             " faces to a line or point; dropped");
  return result;
}

}  // namespace conform::io
