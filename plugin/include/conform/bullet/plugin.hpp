// The one entry point an application attaches to its own Bullet world. It registers a
// btActionInterface (never the world's single tick-callback slot) and detaches on destruction.
//
//   btSoftRigidDynamicsWorld world(...);            // or btSoftMultiBodyDynamicsWorld
//   conform::bullet::Plugin plugin(world);
//   auto arm = conform::skin::make_arm();
//   auto& skin = plugin.add_skinned_body(arm.mesh, arm.skeleton, material);
//   skin.set_keyframes(track);                       // or play(animation), set_pose_source(rig)
//   world.stepSimulation(1.0 / 60);                  // skinning drives the soft body
//   skin.cut(plane);                                 // between steps
//
// Ownership and lifetime: the plugin owns its skinned bodies and they own their pieces'
// btSoftBody objects (skinned_soft_body.hpp). The plugin adds one action and one inert guard
// object (a btCollisionObject with an empty shape, broadphase group and mask 0: it collides
// with nothing) to the world; the guard tells the plugin, when it is destroyed, whether the
// world still exists. Both teardown orders are safe: Bullet's standard one (the application
// removes and deletes every soft body, or every collision object, then destroys the plugin),
// and the world destroyed before the plugin. The world's memory itself must not be reused for
// another world before the plugin goes. The application must not remove the guard from the
// world without deleting it.
//
// Threading: a plugin and its bodies are used from the thread that steps the world, between
// stepSimulation calls (edits inside a step throw std::logic_error); distinct plugins on
// distinct worlds may run on distinct threads. A body's const queries keep no caches: several
// threads may read one body at once while nothing steps or edits it.
#pragma once

#include <functional>
#include <memory>
#include <vector>

#include "conform/bullet/skinned_soft_body.hpp"

class btDynamicsWorld;

namespace conform::io {
struct SkinnedModel;
}

namespace conform::bullet {

class Plugin {
 public:
  /// Called once per internal substep, after motion prediction and before constraints.
  using StepHook = std::function<void(double dt)>;

  /// Any Bullet world for step hooks; skinned bodies need a btSoftRigidDynamicsWorld or a
  /// btSoftMultiBodyDynamicsWorld.
  explicit Plugin(btDynamicsWorld& world);
  ~Plugin();
  Plugin(const Plugin&) = delete;
  Plugin& operator=(const Plugin&) = delete;

  btDynamicsWorld& world() { return *world_; }
  void add_step_hook(StepHook hook);
  /// Substeps seen since construction.
  long long substeps() const;
  /// Simulated time seen by the plugin (sum of substep lengths), s.
  double time() const;

  /// Adds a CGA-skinned soft body built from `mesh` (its current positions) and `skeleton`.
  /// Throws std::logic_error when the world has no soft bodies, std::invalid_argument on bad
  /// input. The body lives as long as the plugin (or until remove_skinned_body).
  /// `settings` (user pointer, collision group and mask, btSoftBody::Config template) apply
  /// to every piece made now, and pieces split later inherit them from their parent.
  SkinnedSoftBody& add_skinned_body(const mesh::SkinnedMesh& mesh, const skin::Skeleton& skeleton,
                                    const Material& material = {},
                                    const PieceSettings& settings = {});
  SkinnedSoftBody& add_skinned_body(const io::SkinnedModel& model, const Material& material = {},
                                    const PieceSettings& settings = {});
  void remove_skinned_body(SkinnedSoftBody& body);
  std::size_t skinned_body_count() const;

 private:
  struct Action;
  struct Guard;
  /// Whether the world is still there (the guard's broadphase handle survives only in it).
  bool world_alive() const;
  btDynamicsWorld* world_;
  std::unique_ptr<Action> action_;
  std::unique_ptr<Guard> guard_;
  bool guard_deleted_ = false;  // the application deleted the guard (it deletes every object)
};

}  // namespace conform::bullet
