#include "render/f3d_render.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <thread>

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

constexpr auto kFeedTimeout = std::chrono::seconds(30);

std::string number(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", x);
  return buf;
}

// Writes all of `bytes` into `fd`. SIGPIPE (f3d gone while reading) is held back for this
// thread and dropped, so that a reader that dies is an EPIPE here, not the end of conform.
bool write_all(int fd, const std::string& bytes) {
  sigset_t pipe, old;
  sigemptyset(&pipe);
  sigaddset(&pipe, SIGPIPE);
  pthread_sigmask(SIG_BLOCK, &pipe, &old);
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += std::size_t(n);
  }
  const timespec none{0, 0};
  while (sigtimedwait(&pipe, nullptr, &none) > 0) {
  }
  pthread_sigmask(SIG_SETMASK, &old, nullptr);
  return done == bytes.size();
}

}  // namespace

std::vector<std::string> f3d_arguments(const std::string& ply, const std::string& png, int width,
                                       int height, double view_angle) {
  // --dry-run: no user configuration file, so every run renders alike (and it halves f3d's
  // start-up). Direct colours (--comp=-2) are the scale's, baked into the PLY.
  return {"f3d",
          "--dry-run",
          "--quiet",
          ply,
          "--output",
          png,
          "--resolution",
          std::to_string(width) + "," + std::to_string(height),
          "--scalars=RGB",
          "--comp=-2",
          "--fxaa",
          "--bg-color",
          "1,1,1",
          "--camera-position",
          "0,0,0",
          "--camera-focal-point",
          "0,0,-1",
          "--camera-view-up",
          "0,1,0",
          "--camera-view-angle",
          number(view_angle)};
}

std::string shell_words(const std::vector<std::string>& args) {
  std::string out;
  for (const auto& a : args) {
    // Single quotes, with any single quote closed, escaped and reopened.
    out += out.empty() ? "'" : " '";
    for (const char c : a) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
    out += "'";
  }
  return out;
}

PrestartedRender::PrestartedRender(fs::path dir, std::string name, int width, int height,
                                   double view_angle, VirtualDisplay* display)
    : fifo_(dir / (name + ".ply")),
      png_(dir / (name + ".png")),
      args_(f3d_arguments(fifo_.string(), png_.string(), width, height, view_angle)),
      width_(width),
      view_angle_(view_angle) {
  fs::remove(fifo_);
  if (::mkfifo(fifo_.c_str(), 0600) != 0) {
    launch_error_ = "cannot make the FIFO " + fifo_.string() + ": " + std::strerror(errno);
    return;
  }
  launcher_ = std::thread([this, display] { launch(display); });
}

void PrestartedRender::launch(VirtualDisplay* display) {
  ChildOptions options;
  options.log = png_.string() + ".log";
  const std::string d = display ? display->display() : std::string();
  std::unique_lock lock(mutex_);
  if (stopping_) launch_error_ = "stopped before it started";
  if (display && d.empty() && launch_error_.empty()) launch_error_ = display->error();
  if (display) options.env.push_back("DISPLAY=" + d);
  ChildProcess f3d;
  if (launch_error_.empty()) f3d = ChildProcess(args_, options);
  if (!f3d.running()) {
    if (launch_error_.empty()) launch_error_ = f3d.error();
    ended_ = true;
    changed_.notify_all();
    return;
  }
  pid_ = f3d.pid();
  changed_.notify_all();
  lock.unlock();
  // Wait for the exit without reaping, so that stop() never signals a pid used again.
  siginfo_t info;
  while (::waitid(P_PID, id_t(pid_), &info, WEXITED | WNOWAIT) < 0 && errno == EINTR) {
  }
  lock.lock();
  ended_ = true;
  status_ = f3d.wait();
  changed_.notify_all();
}

void PrestartedRender::stop() {
  std::lock_guard lock(mutex_);
  stopping_ = true;  // a launch still waiting for the display then starts nothing
  if (pid_ > 0 && !ended_) ::kill(pid_, SIGTERM);
}

PrestartedRender::~PrestartedRender() {
  stop();
  if (launcher_.joinable()) launcher_.join();
  std::error_code ec;
  fs::remove(fifo_, ec);
}

bool PrestartedRender::started(std::string& problem) {
  std::unique_lock lock(mutex_);
  changed_.wait(lock, [&] { return pid_ > 0 || ended_ || !launcher_.joinable(); });
  problem = launch_error_;
  return launch_error_.empty();
}

bool PrestartedRender::feed(const std::string& ply, std::string& problem) {
  if (!started(problem)) return false;
  // Opening a FIFO for writing without blocking fails (ENXIO) until its reader has it open:
  // f3d opens it once started up. Meanwhile f3d may have exited (no display, say).
  const auto until = std::chrono::steady_clock::now() + kFeedTimeout;
  int fd = -1;
  while ((fd = ::open(fifo_.c_str(), O_WRONLY | O_NONBLOCK | O_CLOEXEC)) < 0) {
    if (errno != ENXIO && errno != EINTR) {
      problem = "cannot open " + fifo_.string() + ": " + std::strerror(errno);
      return false;
    }
    {
      std::unique_lock lock(mutex_);
      if (changed_.wait_for(lock, std::chrono::milliseconds(2), [&] { return ended_; })) {
        problem = "f3d exited before reading its surface (see " + png_.string() + ".log)";
        return false;
      }
    }
    if (std::chrono::steady_clock::now() > until) {
      problem = "f3d did not open " + fifo_.string() + " within 30 s";
      return false;
    }
  }
  ::fcntl(fd, F_SETFL, ::fcntl(fd, F_GETFL) & ~O_NONBLOCK);
  fed_ = write_all(fd, ply);
  ::close(fd);
  if (!fed_) problem = "f3d stopped reading " + fifo_.string() + " (see " + png_.string() + ".log)";
  return fed_;
}

bool PrestartedRender::finish(std::string& problem) {
  if (!fed_) stop();  // it would wait for its surface for ever
  if (launcher_.joinable()) launcher_.join();
  std::error_code ec;
  fs::remove(fifo_, ec);
  if (status_ != 0 || !fs::exists(png_)) {
    if (problem.empty())
      problem = "f3d failed (exit " + std::to_string(status_) + ", see " + png_.string() + ".log)";
    return false;
  }
  fs::remove(png_.string() + ".log", ec);
  return true;
}

}  // namespace conform::scenes
