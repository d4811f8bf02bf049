#include "conform/bullet/plugin.hpp"

#include <BulletCollision/CollisionShapes/btEmptyShape.h>
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
  bool stepping = false;  // inside updateAction: edits are refused
  void updateAction(btCollisionWorld*, btScalar dt) override {
    struct Flag {
      bool& on;
      explicit Flag(bool& f) : on(f) { on = true; }
      ~Flag() { on = false; }
      Flag(const Flag&) = delete;
      Flag& operator=(const Flag&) = delete;
    } flag(stepping);
    ++substeps;
    time += static_cast<double>(dt);
    // One pass per substep, before the drive: it sees everything since the last one (the last
    // substep's drive and Bullet's solve, this substep's prediction), and no drive reads a NaN.
    for (std::size_t i = 0; i < bodies.size(); ++i) {
      if (const auto bad = bodies[i]->first_non_finite_node())
        throw NonFiniteState(substeps, time, i, *bad);
      bodies[i]->update(static_cast<double>(dt), time);
    }
    for (auto& hook : hooks) hook(static_cast<double>(dt));
  }
  void debugDraw(btIDebugDraw* drawer) override {
    if (!drawer) return;
    for (auto& body : bodies) body->debug_draw(*drawer);
  }
};

// The world's witness: an object in the world that collides with nothing. Bullet's world
// destructor clears the broadphase handle of every object still in it, so a guard without a
// handle outlived its world. Its destructor tells the plugin when the application deletes it.
struct Plugin::Guard : btCollisionObject {
  btEmptyShape shape;
  bool* deleted;
  explicit Guard(bool* flag) : deleted(flag) {
    setCollisionShape(&shape);
    setCollisionFlags(getCollisionFlags() | CF_NO_CONTACT_RESPONSE | CF_STATIC_OBJECT);
  }
  ~Guard() override {
    if (deleted) *deleted = true;
  }
  Guard(const Guard&) = delete;
  Guard& operator=(const Guard&) = delete;
};

Plugin::Plugin(btDynamicsWorld& world)
    : world_(&world),
      action_(std::make_unique<Action>()),
      guard_(std::make_unique<Guard>(&guard_deleted_)) {
  world_->addAction(action_.get());
  world_->addCollisionObject(guard_.get(), 0, 0);
}

bool Plugin::world_alive() const {
  // A guard deleted by the application: it removed the objects of a live world (Bullet's rule).
  return guard_deleted_ || guard_->getBroadphaseHandle() != nullptr;
}

Plugin::~Plugin() {
  const bool alive = world_alive();
  action_->bodies.clear();  // their pieces leave the world first (if it is still there)
  if (guard_deleted_)
    (void)guard_.release();  // the application's delete freed it
  else
    guard_->deleted = nullptr;
  if (!alive) return;  // nothing of a destroyed world may be touched
  if (guard_) world_->removeCollisionObject(guard_.get());
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
                                          const skin::Skeleton& skeleton, const Material& material,
                                          const PieceSettings& settings) {
  WorldLink link;
  switch (world_->getWorldType()) {
    case BT_SOFT_RIGID_DYNAMICS_WORLD: {
      auto* w = static_cast<btSoftRigidDynamicsWorld*>(world_);
      link.info = &w->getWorldInfo();
      link.add = [w](btSoftBody* b, int group, int mask) { w->addSoftBody(b, group, mask); };
      link.remove = [w](btSoftBody* b) { w->removeSoftBody(b); };
      break;
    }
    case BT_SOFT_MULTIBODY_DYNAMICS_WORLD: {
      auto* w = static_cast<btSoftMultiBodyDynamicsWorld*>(world_);
      link.info = &w->getWorldInfo();
      link.add = [w](btSoftBody* b, int group, int mask) { w->addSoftBody(b, group, mask); };
      link.remove = [w](btSoftBody* b) { w->removeSoftBody(b); };
      break;
    }
    default:
      throw std::logic_error(
          "add_skinned_body needs a btSoftRigidDynamicsWorld or btSoftMultiBodyDynamicsWorld");
  }
  if (action_->stepping)
    throw std::logic_error(
        "Plugin::add_skinned_body: called inside stepSimulation; add bodies "
        "between steps");
  link.stepping = [action = action_.get()] { return action->stepping; };
  action_->bodies.push_back(
      std::make_unique<SkinnedSoftBody>(link, mesh, skeleton, material, settings));
  return *action_->bodies.back();
}

SkinnedSoftBody& Plugin::add_skinned_body(const io::SkinnedModel& model, const Material& material,
                                          const PieceSettings& settings) {
  return add_skinned_body(model.mesh, model.skeleton, material, settings);
}

void Plugin::remove_skinned_body(SkinnedSoftBody& body) {
  if (action_->stepping)
    throw std::logic_error(
        "Plugin::remove_skinned_body: called inside stepSimulation; remove "
        "bodies between steps");
  auto& list = action_->bodies;
  list.erase(std::remove_if(list.begin(), list.end(), [&](auto& b) { return b.get() == &body; }),
             list.end());
}

std::size_t Plugin::skinned_body_count() const {
  return action_->bodies.size();
}

}  // namespace conform::bullet
