// One render by Debian's f3d (1.3): a PLY surface with direct RGB colours, written in its
// camera's view frame (event_camera.hpp, ViewFrame), into a PNG. Every render's camera is then
// view_frame_camera(view angle), known before the event is, which lets an f3d start before its
// surface exists (PrestartedRender).
//
// Why start early: an f3d render of the default scene's last frame costs about 0.35 s, and about
// 0.2 s of it is f3d starting up (VTK's libraries relocated, the X display connected, the
// render window made) before it reads anything. Started when the run's first frame is offered,
// that part runs on a free core while the scene simulates; f3d then blocks opening a FIFO
// where its PLY file would be, until the last frame is written into it.
#pragma once

#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "base/child_process.hpp"
#include "render/virtual_display.hpp"

namespace conform::scenes {

/// f3d's arguments for rendering `ply` into `png`, width x height pixels, through
/// view_frame_camera(view_angle) (degrees, vertical), on a white background.
std::vector<std::string> f3d_arguments(const std::string& ply, const std::string& png, int width,
                                       int height, double view_angle);

/// The arguments as one sh command line, each quoted.
std::string shell_words(const std::vector<std::string>& args);

/// An f3d render started before its surface exists: f3d reads `dir/name.ply`, a FIFO, and
/// renders into `dir/name.png` (its output in `dir/name.png.log`).
class PrestartedRender {
 public:
  /// Makes the FIFO and starts f3d, in a thread of its own, once `display` (when not null) is
  /// up: the caller does not wait for the display.
  PrestartedRender(std::filesystem::path dir, std::string name, int width, int height,
                   double view_angle, VirtualDisplay* display);
  /// Stops f3d if it still runs and removes the FIFO.
  ~PrestartedRender();

  /// Hands the surface (a whole PLY file) to f3d. False, with `problem` set, when f3d is not
  /// there to take it (it exited; it then waits no more than 30 s for f3d to open the FIFO).
  bool feed(const std::string& ply, std::string& problem);
  /// Waits for a fed f3d to finish (stops one that was not fed); false, with `problem` set,
  /// unless it exited 0 with its PNG.
  bool finish(std::string& problem);

  const std::filesystem::path& png() const { return png_; }
  const std::vector<std::string>& arguments() const { return args_; }
  int width() const { return width_; }
  double view_angle() const { return view_angle_; }

  PrestartedRender(const PrestartedRender&) = delete;
  PrestartedRender& operator=(const PrestartedRender&) = delete;

 private:
  // The launching thread's work: it waits for the display, starts f3d and waits for it to exit.
  // f3d must be its child for as long as it runs: the kernel's parent-death signal
  // (ChildProcess) follows the thread that forked, not the process.
  void launch(VirtualDisplay* display);
  void stop();
  // Waits until f3d is started (or could not be): false, with `problem` set, when it could
  // not.
  bool started(std::string& problem);

  std::filesystem::path fifo_, png_;
  std::vector<std::string> args_;
  int width_;
  double view_angle_;
  bool fed_ = false;
  std::mutex mutex_;  // guards the state below, shared with the launching thread
  std::condition_variable changed_;
  pid_t pid_ = -1;         // f3d, once started
  bool stopping_ = false;  // stop() came: no f3d is to be started any more
  bool ended_ = false;     // f3d has exited (or was never started), launch_error_ then says why
  int status_ = -1;        // f3d's exit status, once reaped
  std::string launch_error_;
  std::thread launcher_;  // last: it starts once the members above are made
};

}  // namespace conform::scenes
