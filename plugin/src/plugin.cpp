#include "conform/bullet/plugin.hpp"

#include <BulletDynamics/Dynamics/btActionInterface.h>
#include <BulletDynamics/Dynamics/btDynamicsWorld.h>

#include "conform/bullet/convert.hpp"

namespace conform::bullet {

struct Plugin::Action : btActionInterface {
  std::vector<StepHook> hooks;
  long long substeps = 0;
  void updateAction(btCollisionWorld*, btScalar dt) override {
    ++substeps;
    for (auto& hook : hooks) hook(static_cast<double>(dt));
  }
  void debugDraw(btIDebugDraw*) override {}
};

Plugin::Plugin(btDynamicsWorld& world) : world_(&world), action_(std::make_unique<Action>()) {
  world_->addAction(action_.get());
}

Plugin::~Plugin() { world_->removeAction(action_.get()); }

void Plugin::add_step_hook(StepHook hook) { action_->hooks.push_back(std::move(hook)); }

long long Plugin::substeps() const { return action_->substeps; }

cga::Motor<double> to_motor(const btTransform& transform) {
  const btQuaternion q = transform.getRotation();
  const btVector3& t = transform.getOrigin();
  return cga::Motor<double>::from_rotation_translation(
      cga::Quat<double>(q.w(), q.x(), q.y(), q.z()), cga::Vec3<double>(t.x(), t.y(), t.z()));
}

btTransform to_transform(const cga::Motor<double>& motor) {
  const cga::Quat<double> q = motor.rotation().normalized();
  const cga::Vec3<double> t = motor.translation();
  return btTransform(btQuaternion(btScalar(q.x()), btScalar(q.y()), btScalar(q.z()), btScalar(q.w())),
                     to_bt(t));
}

const char* bullet_precision() {
#ifdef BT_USE_DOUBLE_PRECISION
  return "double";
#else
  return "float";
#endif
}

}  // namespace conform::bullet
