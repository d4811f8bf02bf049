#include "kinds/model_frame.hpp"

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <numbers>
#include <stdexcept>

namespace conform::scenes {
namespace {

// The rotation from the file's axes to Y up: −90° about x takes +z to +y.
Eigen::Quaterniond up_rotation(const std::string& up) {
  if (up == "y") return Eigen::Quaterniond::Identity();
  if (up == "z")
    return Eigen::Quaterniond(Eigen::AngleAxisd(-std::numbers::pi / 2, Eigen::Vector3d::UnitX()));
  throw std::invalid_argument("model.up = \"" + up + "\": must be \"y\" or \"z\"");
}

// A root joint in front of the others: parents first stays true, indices shift by one.
void insert_root(io::SkinnedModel& model, const skin::Versor& root) {
  for (auto& j : model.skeleton.joints) ++j.parent;  // old roots (−1) hang from the new one (0)
  model.skeleton.joints.insert(model.skeleton.joints.begin(),
                               skin::Joint{"(scene frame)", -1, root});
  for (auto& b : model.skeleton.bones) ++b.joint;
  for (auto& a : model.animations)
    for (auto& c : a.channels) ++c.joint;
  for (auto& m : model.meshes) ++m.joint;
}

}  // namespace

void to_scene_frame(io::SkinnedModel& model, const ModelFrame& frame) {
  const Eigen::Quaterniond q = up_rotation(frame.up);
  const double s = 1 / frame.units_per_metre;
  if (s == 1 && frame.up == "y") return;  // the file is in the scene's frame already
  model.mesh.rest *= s;
  for (auto& b : model.skeleton.bones)
    b.offset = b.offset * skin::Versor{{}, frame.units_per_metre};
  insert_root(model, skin::Versor::from_trs(Eigen::Vector3d::Zero(), q, s));
  const Eigen::Matrix3d r = q.toRotationMatrix();
  model.mesh.current = (s * r) * model.mesh.current;
  if (model.mesh.normals.cols() > 0) model.mesh.normals = r * model.mesh.normals;
  auto& corners = model.mesh.corner_normals;
  for (Eigen::Index c = 0; c < corners.cols(); ++c)
    for (int k = 0; k < 3; ++k)
      corners.col(c).segment<3>(3 * k) = r * corners.col(c).segment<3>(3 * k);
}

FileUnits file_units(const io::SkinnedModel& model, const std::string& file) {
  if (model.unit_scale_cm <= 0)
    return {1, "assumed: metres (the file states no unit; set model.units_per_metre)"};
  const std::string cm = nlohmann::json(model.unit_scale_cm).dump();
  const double units = 100 / model.unit_scale_cm;
  if (!(units >= 1e-6 && units <= 1e6))
    throw std::runtime_error(file + ": its UnitScaleFactor " + cm +
                             " cm is out of range; set model.units_per_metre");
  return {units, "the file's UnitScaleFactor (" + cm + " cm)"};
}

}  // namespace conform::scenes
