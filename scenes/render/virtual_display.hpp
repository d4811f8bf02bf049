// A virtual X display (Xvfb) for f3d's renders when conform has no display of its own.
//
// It is started when a run that renders begins, so that the server's start-up (about 0.15 s,
// as long as a third of the default scene's simulation) overlaps the simulation instead of
// delaying the pictures, as xvfb-run did. It is conform's child: stopped with the run, and
// killed by the kernel if conform dies first (PR_SET_PDEATHSIG), so no server outlives a run.
#pragma once

#include <mutex>
#include <string>

#include "base/child_process.hpp"

namespace conform::scenes {

class VirtualDisplay {
 public:
  /// Starts Xvfb with one screen of width x height x 24 bits on the first free display number
  /// (Xvfb -displayfd). Does not wait for it: see display().
  VirtualDisplay(int width, int height);
  /// Stops the server (SIGTERM, then waits for it: ChildProcess).
  ~VirtualDisplay();

  /// Waits until the server listens (at most 10 s) and returns its display, ":N"; "" when it
  /// could not start, error() then says why. Safe to call from any thread.
  const std::string& display();
  const std::string& error() const { return error_; }

  VirtualDisplay(const VirtualDisplay&) = delete;
  VirtualDisplay& operator=(const VirtualDisplay&) = delete;

 private:
  ChildProcess server_;
  std::mutex mutex_;   // display() may be first asked from a render's launching thread
  int ready_fd_ = -1;  // Xvfb writes its display number here once it listens
  std::string display_, error_;
};

}  // namespace conform::scenes
