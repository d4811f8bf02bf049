// The Python World and Body: a Bullet soft world with ground, gravity and the plugin, and the
// skinned soft bodies the plugin owns, seen from Python.
#pragma once

#include <btBulletDynamicsCommon.h>

#include <Eigen/Core>
#include <memory>
#include <optional>
#include <vector>

#include "bindings.hpp"
#include "conform/bullet/plugin.hpp"
#include "conform/bullet/soft_world.hpp"
#include "conform/skin/animation.hpp"

namespace conform::python {

/// A soft world (gravity, an optional ground: a static box whose top is y = height) with the
/// plugin attached. It owns every body added to it; a Body keeps its World alive.
struct World {
  bullet::SoftWorld soft;
  std::unique_ptr<btCollisionShape> ground_shape;
  std::unique_ptr<btDefaultMotionState> ground_motion;
  std::unique_ptr<btRigidBody> ground;
  std::unique_ptr<bullet::Plugin> plugin;
  World(const Eigen::Vector3d& gravity, std::optional<double> ground_height);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;
};

/// A body's piece events, shared by the plugin's listener and the Python Body (either may
/// outlive the other).
struct PieceEvents {
  std::vector<bullet::PieceEvent> log;          // since the last Body.events()
  std::vector<bullet::PieceEvent> undelivered;  // not yet given to the Python listeners
  std::vector<py::object> listeners;
};

/// A SkinnedSoftBody owned by its World's plugin, kept alive by `world`.
struct Body {
  bullet::SkinnedSoftBody* body = nullptr;
  py::object world;
  std::vector<skin::Animation> animations;  // a model file's
  /// Live zero-copy views of the body's vertex and face storage (body_arrays.cpp).
  std::shared_ptr<int> views = std::make_shared<int>(0);
  std::shared_ptr<PieceEvents> events = std::make_shared<PieceEvents>();

  bullet::SkinnedSoftBody& get() const { return *body; }
  /// `v` when it names a vertex; else throws std::out_of_range (IndexError).
  std::int32_t vertex(std::int32_t v) const;
  /// Throws BufferError while views of the storage an edit may move are alive.
  void check_no_views(const char* edit) const;
  /// Calls the Python listeners with the events queued since the last call.
  void deliver_events();
};

/// Makes the Python Body of a body just added to `world` (listens to its piece events).
Body make_body(const py::object& world, bullet::SkinnedSoftBody& body);

void bind_body_state(py::class_<Body>& c);   // body.cpp: state, pieces, events, pose
void bind_body_arrays(py::class_<Body>& c);  // body_arrays.cpp: numpy arrays
void bind_body_edits(py::class_<Body>& c);   // body_edits.cpp: cut, tear, drill

}  // namespace conform::python
