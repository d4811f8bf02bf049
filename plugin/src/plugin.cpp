#include "conform/bullet/plugin.hpp"

#include <BulletDynamics/Dynamics/btActionInterface.h>
#include <BulletDynamics/Dynamics/btDynamicsWorld.h>
#include <BulletSoftBody/btSoftMultiBodyDynamicsWorld.h>
#include <BulletSoftBody/btSoftRigidDynamicsWorld.h>

#include <algorithm>
#include <stdexcept>

#include "conform/bullet/convert.hpp"
#include "conform/io/model.hpp"

namespace conform::bullet {

struct Plugin::Action : btActionInterface {
  std::vector<StepHook> hooks;
  std::vector<std::unique_ptr<SkinnedSoftBody>> bodies;
  long long substeps = 0;
  double time = 0;
  void updateAction(btCollisionWorld*, btScalar dt) override {
    ++substeps;
    time += static_cast<double>(dt);
    for (auto& body : bodies) body->update(static_cast<double>(dt), time);
    for (auto& hook : hooks) hook(static_cast<double>(dt));
  }
  void debugDraw(btIDebugDraw*) override {}
};

Plugin::Plugin(btDynamicsWorld& world) : world_(&world), action_(std::make_unique<Action>()) {
  world_->addAction(action_.get());
}

Plugin::~Plugin() {
  action_->bodies.clear();  // their pieces leave the world first
  world_->removeAction(action_.get());
}

void Plugin::add_step_hook(StepHook hook) {
  action_->hooks.push_back(std::move(hook));
}

long long Plugin::substeps() const {
  return action_->substeps;
}

double Plugin::time() const {
  return action_->time;
}

SkinnedSoftBody& Plugin::add_skinned_body(const mesh::SkinnedMesh& mesh,
                                          const skin::Skeleton& skeleton,
                                          const Material& material) {
  btSoftBodyWorldInfo* info = nullptr;
  std::function<void(btSoftBody*)> add, remove;
  switch (world_->getWorldType()) {
    case BT_SOFT_RIGID_DYNAMICS_WORLD: {
      auto* w = static_cast<btSoftRigidDynamicsWorld*>(world_);
      info = &w->getWorldInfo();
      add = [w](btSoftBody* b) { w->addSoftBody(b); };
      remove = [w](btSoftBody* b) { w->removeSoftBody(b); };
      break;
    }
    case BT_SOFT_MULTIBODY_DYNAMICS_WORLD: {
      auto* w = static_cast<btSoftMultiBodyDynamicsWorld*>(world_);
      info = &w->getWorldInfo();
      add = [w](btSoftBody* b) { w->addSoftBody(b); };
      remove = [w](btSoftBody* b) { w->removeSoftBody(b); };
      break;
    }
    default:
      throw std::logic_error(
          "add_skinned_body needs a btSoftRigidDynamicsWorld or btSoftMultiBodyDynamicsWorld");
  }
  action_->bodies.push_back(
      std::make_unique<SkinnedSoftBody>(*info, add, remove, mesh, skeleton, material));
  return *action_->bodies.back();
}

SkinnedSoftBody& Plugin::add_skinned_body(const io::SkinnedModel& model, const Material& material) {
  return add_skinned_body(model.mesh, model.skeleton, material);
}

void Plugin::remove_skinned_body(SkinnedSoftBody& body) {
  auto& list = action_->bodies;
  list.erase(std::remove_if(list.begin(), list.end(), [&](auto& b) { return b.get() == &body; }),
             list.end());
}

std::size_t Plugin::skinned_body_count() const {
  return action_->bodies.size();
}

}  // namespace conform::bullet
