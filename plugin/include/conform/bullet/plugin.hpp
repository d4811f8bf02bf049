// The one entry point an application attaches to its own Bullet world. It registers a
// btActionInterface (never the world's single tick-callback slot) and detaches on destruction.
#pragma once

#include <functional>
#include <memory>
#include <vector>

class btDynamicsWorld;

namespace conform::bullet {

class Plugin {
 public:
  /// Called once per internal substep, after motion prediction and before constraints.
  using StepHook = std::function<void(double dt)>;

  explicit Plugin(btDynamicsWorld& world);
  ~Plugin();
  Plugin(const Plugin&) = delete;
  Plugin& operator=(const Plugin&) = delete;

  btDynamicsWorld& world() { return *world_; }
  void add_step_hook(StepHook hook);
  /// Substeps seen since construction.
  long long substeps() const;

 private:
  struct Action;
  btDynamicsWorld* world_;
  std::unique_ptr<Action> action_;
};

}  // namespace conform::bullet
