#include "conform/skin/skinner.hpp"

#include <stdexcept>
#include <utility>

namespace conform::skin {

std::optional<SkinMode> parse_skin_mode(std::string_view text) {
  if (text == "lbs" || text == "cga") return SkinMode::cga;
  if (text == "versor") return SkinMode::versor;
  if (text == "matrix") return SkinMode::matrix_lbs;
  if (text == "dq") return SkinMode::dual_quaternion;
  return std::nullopt;
}

const char* skin_mode_name(SkinMode mode) {
  switch (mode) {
    case SkinMode::cga:
      return "cga";
    case SkinMode::versor:
      return "versor";
    case SkinMode::matrix_lbs:
      return "matrix";
    case SkinMode::dual_quaternion:
      return "dq";
  }
  return "?";
}

template <class T>
Skinner<T>::Skinner(const Skeleton& skeleton, Eigen::Ref<const Eigen::Matrix3Xd> rest,
                    const InfluenceLists& influences, int max_influences)
    : Skinner(skeleton, rest, Influences<T>::select(influences, max_influences)) {}

template <class T>
Skinner<T>::Skinner(const Skeleton& skeleton, Eigen::Ref<const Eigen::Matrix3Xd> rest,
                    Influences<T> influences)
    : skeleton_(&skeleton),
      global_(skeleton.joints.size()),
      skin_versors_(skeleton.bones.size()),
      kernels_(skeleton.bones.size()),
      coefficients_(skeleton.bones.size()),
      dq_(skeleton.bones.size()),
      matrices_(skeleton) {
  if (influences.vertex_count != rest.cols())
    throw std::invalid_argument("Skinner: influences and positions differ in vertex count");
  if (const auto e = skeleton.validate(); !e.empty()) throw std::invalid_argument("Skinner: " + e);
  set_points(rest, std::move(influences));
}

template <class T>
void Skinner<T>::set_points(Eigen::Ref<const Eigen::Matrix3Xd> rest, Influences<T> influences) {
  if (influences.vertex_count != rest.cols())
    throw std::invalid_argument("Skinner: influences and positions differ in vertex count");
  SoaPoints<T> points = SoaPoints<T>::from(rest), out;
  out.resize(points.size());
  const SkinInput<T> in{points.x,         points.y,         points.z,
                        influences.count, influences.bones, influences.weights};
  if (const auto e = validate_skin_io(in, {out.x, out.y, out.z}, skeleton_->bones.size());
      !e.empty())
    throw std::invalid_argument("Skinner: " + e);
  rest_ = std::move(points);
  out_ = std::move(out);
  influences_ = std::move(influences);
}

template <class T>
SkinInput<T> Skinner<T>::input() const {
  return {rest_.x, rest_.y, rest_.z, influences_.count, influences_.bones, influences_.weights};
}

template <class T>
SkinOutput<T> Skinner<T>::output_span() {
  return {out_.x, out_.y, out_.z};
}

template <class T>
void Skinner<T>::prepare(const Pose& pose, SkinMode mode) {
  if (mode == SkinMode::cga || mode == SkinMode::versor) {
    global_versors(*skeleton_, pose, global_);
    skin::skinning_versors(*skeleton_, global_, skin_versors_);
    if (mode == SkinMode::cga)
      versor_kernels<T>(skin_versors_, kernels_);
    else
      versor_coefficients<T>(skin_versors_, coefficients_);
  } else {
    matrices_.update(pose);
    if (mode == SkinMode::matrix_lbs)
      matrices_.kernels<T>(kernels_);
    else
      dq_bones<T>(matrices_.skinning_matrices(), dq_);
  }
}

template <class T>
void Skinner<T>::run(SkinMode mode) {
  run(mode, output_span());
}

template <class T>
void Skinner<T>::run(SkinMode mode, SkinOutput<T> out) {
  switch (mode) {
    case SkinMode::cga:
      CgaSkinningJob<T>{kernels_, input(), out, threads_}.run();
      break;
    case SkinMode::versor:
      VersorBlendJob<T>{coefficients_, input(), out, threads_}.run();
      break;
    case SkinMode::matrix_lbs:
      LbsSkinningJob<T>{kernels_, input(), out, threads_}.run();
      break;
    case SkinMode::dual_quaternion:
      DqSkinningJob<T>{dq_, input(), out, threads_}.run();
      break;
  }
}

template <class T>
void Skinner<T>::skin(const Pose& pose, SkinMode mode) {
  prepare(pose, mode);
  run(mode);
}

template <class T>
void Skinner<T>::skin(const Pose& pose, SkinMode mode, SoaPoints<T>& out) {
  prepare(pose, mode);
  out.resize(rest_.size());
  run(mode, {out.x, out.y, out.z});
}

template class Skinner<float>;
template class Skinner<double>;

}  // namespace conform::skin
