#include "conform/skin/skinner.hpp"

#include <stdexcept>

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
    : skeleton_(&skeleton),
      rest_(SoaPoints<T>::from(rest)),
      influences_(Influences<T>::select(influences, max_influences)),
      global_(skeleton.joints.size()),
      skin_versors_(skeleton.bones.size()),
      kernels_(skeleton.bones.size()),
      coefficients_(skeleton.bones.size()),
      dq_(skeleton.bones.size()),
      matrices_(skeleton) {
  if (influences.vertex_count() != rest.cols())
    throw std::invalid_argument("Skinner: influences and positions differ in vertex count");
  if (const auto e = skeleton.validate(); !e.empty()) throw std::invalid_argument("Skinner: " + e);
  out_.resize(rest_.size());
  if (const auto e = validate_skin_io(input(), output_span(), skeleton.bones.size()); !e.empty())
    throw std::invalid_argument("Skinner: " + e);
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
  switch (mode) {
    case SkinMode::cga:
      CgaSkinningJob<T>{kernels_, input(), output_span(), threads_}.run();
      break;
    case SkinMode::versor:
      VersorBlendJob<T>{coefficients_, input(), output_span(), threads_}.run();
      break;
    case SkinMode::matrix_lbs:
      LbsSkinningJob<T>{kernels_, input(), output_span(), threads_}.run();
      break;
    case SkinMode::dual_quaternion:
      DqSkinningJob<T>{dq_, input(), output_span(), threads_}.run();
      break;
  }
}

template <class T>
void Skinner<T>::skin(const Pose& pose, SkinMode mode) {
  prepare(pose, mode);
  run(mode);
}

template class Skinner<float>;
template class Skinner<double>;

}  // namespace conform::skin
