#include "material_fit.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace conform::bullet {
namespace {

// The link-only fields (kLinkOnlyFields) that differ from their defaults.
std::vector<std::string> set_link_fields(const Material& m) {
  const Material d;
  std::vector<std::string> out;
  for (const MaterialField& f : kLinkOnlyFields)
    if (m.*f.value != d.*f.value) out.push_back(f.name);
  return out;
}

// The median edge length of the faces at `rest`, m (0 without faces).
double median_edge(const Eigen::Ref<const Eigen::Matrix3Xd>& rest,
                   std::span<const mesh::Face> faces) {
  std::vector<double> edges;
  edges.reserve(3 * faces.size());
  for (const mesh::Face& f : faces)
    for (int k = 0; k < 3; ++k) edges.push_back((rest.col(f[k]) - rest.col(f[(k + 1) % 3])).norm());
  if (edges.empty()) return 0;
  std::nth_element(edges.begin(), edges.begin() + std::ptrdiff_t(edges.size() / 2), edges.end());
  return edges[edges.size() / 2];
}

}  // namespace

std::vector<std::string> material_fit_warnings(const Material& material,
                                               const Eigen::Ref<const Eigen::Matrix3Xd>& rest,
                                               std::span<const mesh::Face> faces) {
  std::vector<std::string> out;
  if (material.model != MaterialModel::membrane) return out;
  const std::vector<std::string> links = set_link_fields(material);
  if (!links.empty()) {
    std::string names;
    for (const std::string& n : links) names += (names.empty() ? "" : ", ") + n;
    out.push_back("material " + names + " set, but the model is the membrane, which ignores " +
                  (links.size() > 1 ? "them" : "it") + " (bullet_links fields)");
  }
  // The attachment's decay length l = sqrt(E'' t / k): over it the skin's own tension spreads.
  // Below about half an element, each node is held alone and the skin's mechanics (a wound's
  // opening, its growth) is the mesh's, not the material's.
  const membrane::SkinMaterial& s = material.skin;
  const double k = s.attachment_stiffness, edge = median_edge(rest, faces);
  if (k > 0 && edge > 0) {
    const double modulus = membrane::small_strain_moduli(s).c11;
    const double decay = std::sqrt(modulus * s.thickness / k);
    if (decay < 0.5 * edge) {
      std::ostringstream w;
      w.precision(3);
      w << "material skin.attachment_stiffness = " << k << " Pa/m: the attachment's decay length "
        << "sqrt(E'' t / k) = " << decay << " m is below half the median edge (" << edge
        << " m): the skin's tension acts element by element; refine the mesh or lower the "
           "attachment stiffness";
      out.push_back(w.str());
    }
  }
  return out;
}

}  // namespace conform::bullet
