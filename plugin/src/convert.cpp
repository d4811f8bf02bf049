// Conversions between Conform's algebra and Bullet's types (convert.hpp).
#include "conform/bullet/convert.hpp"

namespace conform::bullet {

cga::Motor<double> to_motor(const btTransform& transform) {
  const btQuaternion q = transform.getRotation();
  const btVector3& t = transform.getOrigin();
  return cga::Motor<double>::from_rotation_translation(
      cga::Quat<double>(q.w(), q.x(), q.y(), q.z()), from_bt(t));
}

btTransform to_transform(const cga::Motor<double>& motor) {
  const cga::Quat<double> q = motor.rotation().normalized();
  const cga::Vec3<double> t = motor.translation();
  return btTransform(
      btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())), to_bt(t));
}

const char* bullet_precision() {
#ifdef BT_USE_DOUBLE_PRECISION
  return "double";
#else
  return "float";
#endif
}

}  // namespace conform::bullet
