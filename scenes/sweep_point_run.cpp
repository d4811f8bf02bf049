#include "sweep_point_run.hpp"

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <fstream>

extern char** environ;

namespace conform::scenes {

namespace fs = std::filesystem;

double monotonic_seconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

fs::path point_record(const fs::path& dir, int index, const std::string& ext) {
  fs::path p = point_dir(dir, index);
  return p.replace_filename(p.filename().string() + "." + ext);
}

bool summary_complete(const fs::path& folder) {
  std::ifstream in(folder / "summary.json");
  if (!in) return false;
  const Json j = Json::parse(in, nullptr, /*allow_exceptions=*/false);
  return j.is_object() && j.contains("metrics") && j["metrics"].is_object() &&
         j.contains("timings") && j["timings"].is_object();
}

PointStatus read_status(const fs::path& dir, int index) {
  PointStatus s;
  std::ifstream in(point_record(dir, index, "status.json"));
  const Json j = in ? Json::parse(in, nullptr, false) : Json();
  if (j.is_object()) {
    s.exit_code = j.value("exit_code", -1);
    s.error = j.value("error", "");
    s.wall_s = j.value("wall_s", 0.0);
  }
  if (summary_complete(point_dir(dir, index))) {
    s.state = PointStatus::State::Done;
    if (s.exit_code < 0) s.exit_code = 0;  // finished, but its status was not recorded
  } else if (j.is_object() && s.exit_code != 0) {
    s.state = PointStatus::State::Failed;
  }
  return s;
}

PointProcess start_point(const SweepSpec& spec, const fs::path& dir, int index) {
  const fs::path folder = point_dir(dir, index);
  std::error_code ec;
  fs::create_directories(folder.parent_path(), ec);
  if (ec)
    throw std::runtime_error("cannot create " + folder.parent_path().string() + ": " +
                             ec.message());
  // A stale failure must not outlive a new attempt.
  fs::remove(point_record(dir, index, "status.json"), ec);
  std::vector<std::string> args = spec.run_arguments(spec.points.at(std::size_t(index)), folder);
  args.insert(args.begin(), "conform");
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  const std::string log = point_record(dir, index, "out").string(),
                    err = point_record(dir, index, "err").string();
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, err.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  PointProcess p;
  p.index = index;
  p.started = monotonic_seconds();
  // The same binary as this process, whatever PATH says.
  const int rc = posix_spawn(&p.pid, "/proc/self/exe", &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0)
    throw std::runtime_error("cannot start conform run for point " + std::to_string(index) + ": " +
                             std::strerror(rc));
  return p;
}

namespace {

std::string last_line(const fs::path& file) {
  std::ifstream in(file);
  std::string line, last;
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

}  // namespace

PointStatus finish_point(const fs::path& dir, const PointProcess& process, int wstatus) {
  const fs::path folder = point_dir(dir, process.index);
  PointStatus s;
  s.wall_s = monotonic_seconds() - process.started;
  if (WIFEXITED(wstatus)) {
    s.exit_code = WEXITSTATUS(wstatus);
    if (s.exit_code != 0) s.error = last_line(point_record(dir, process.index, "err"));
  } else if (WIFSIGNALED(wstatus)) {
    s.exit_code = 128 + WTERMSIG(wstatus);
    s.error = std::string("killed by signal ") + std::to_string(WTERMSIG(wstatus)) + " (" +
              strsignal(WTERMSIG(wstatus)) + ")";
  }
  if (s.exit_code == 0 && !summary_complete(folder)) {
    s.exit_code = 1;
    s.error = "conform run exited 0 but wrote no complete summary.json";
  }
  if (s.exit_code != 0 && s.error.empty()) s.error = "exit status " + std::to_string(s.exit_code);
  s.state = s.exit_code == 0 ? PointStatus::State::Done : PointStatus::State::Failed;
  const Json j = {{"index", process.index},
                  {"exit_code", s.exit_code},
                  {"error", s.error},
                  {"wall_s", s.wall_s}};
  const fs::path record = point_record(dir, process.index, "status.json");
  const fs::path tmp = record.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << j.dump(2) << "\n";
  }
  std::error_code ec;
  fs::rename(tmp, record, ec);
  return s;
}

}  // namespace conform::scenes
