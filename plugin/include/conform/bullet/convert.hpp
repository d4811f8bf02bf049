// Conversions between Conform's algebra and Bullet's types (btScalar follows Bullet's build).
#pragma once

#include "conform/bullet/precision.hpp"  // the package's Bullet precision, checked

#include <LinearMath/btTransform.h>

#include "conform/cga/motor.hpp"

namespace conform::bullet {

cga::Motor<double> to_motor(const btTransform& transform);
btTransform to_transform(const cga::Motor<double>& motor);
inline btVector3 to_bt(const cga::Vec3<double>& v) {
  return btVector3(btScalar(v.x()), btScalar(v.y()), btScalar(v.z()));
}
inline cga::Vec3<double> from_bt(const btVector3& v) {
  return {v.x(), v.y(), v.z()};
}

/// "double" when Bullet was built with BT_USE_DOUBLE_PRECISION, else "float".
const char* bullet_precision();

}  // namespace conform::bullet
