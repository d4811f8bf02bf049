#include "sweep_slurm.hpp"

#include <cctype>

#include <cstdio>
#include <fstream>

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

// Single quotes for the shell: the folder and binary paths may hold spaces.
std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// Values go into #SBATCH lines, which Slurm reads up to the end of the line: no spaces or
// line breaks, so an option cannot smuggle in another directive.
void check_word(const std::string& option, const std::string& value) {
  if (value.find_first_of(" \t\r\n'\"#") != std::string::npos)
    throw SceneError(option, "\"" + value + "\"", "must be one word (no spaces, quotes or #)");
}

// Slurm's time forms: MINUTES, MM:SS, HH:MM:SS, D-HH, D-HH:MM, D-HH:MM:SS — an optional
// "DAYS-", then one to three groups of digits joined by ':'. (Not std::regex: GCC 12's
// -Wmaybe-uninitialized fires inside <regex> in the sanitized build.)
bool is_slurm_time(const std::string& t) {
  std::size_t at = 0;
  const auto digits = [&] {
    const std::size_t from = at;
    while (at < t.size() && std::isdigit(static_cast<unsigned char>(t[at]))) ++at;
    return at > from;
  };
  if (const auto dash = t.find('-'); dash != std::string::npos) {
    if (!digits() || at != dash) return false;
    ++at;
  }
  for (int group = 0; group < 3; ++group) {
    if (!digits()) return false;
    if (at == t.size()) return true;
    if (t[at++] != ':') return false;
  }
  return false;
}

}  // namespace

void check_slurm_options(const SlurmOptions& options) {
  check_word("--partition", options.partition);
  check_word("--time", options.time);
  if (!options.time.empty() && !is_slurm_time(options.time))
    throw SceneError("--time", options.time,
                     "is not a Slurm time (MINUTES, HH:MM:SS, D-HH:MM:SS, ...)");
  if (options.array_limit < 0)
    throw SceneError("--array-limit", std::to_string(options.array_limit), "must be >= 0");
}

fs::path write_sbatch(const SweepSpec& spec, const fs::path& dir, const fs::path& conform,
                      const SlurmOptions& options) {
  check_slurm_options(options);
  const fs::path abs = fs::absolute(dir).lexically_normal();
  std::error_code ec;
  fs::create_directories(abs / "slurm", ec);
  if (ec) throw std::runtime_error("cannot create " + (abs / "slurm").string());
  const fs::path file = abs / "sweep.sbatch";
  std::ofstream out(file);
  out << "#!/bin/bash\n"
      << "# conform sweep of " << spec.scene << ": " << spec.points.size()
      << " points, one array task each.\n"
      << "# Task N runs point N into runs/N (see sweep.json); finished points are skipped,\n"
      << "# so resubmitting the array reruns only what is missing. Afterwards:\n"
      << "#   conform sweep --gather " << abs.string() << "\n"
      << "#SBATCH --job-name=" << options.job_name << "\n"
      << "#SBATCH --array=0-" << (spec.points.size() - 1)
      << (options.array_limit > 0 ? "%" + std::to_string(options.array_limit) : "") << "\n"
      << "#SBATCH --ntasks=1\n"
      << "#SBATCH --cpus-per-task=1\n"
      << "#SBATCH --chdir=" << abs.string() << "\n"
      << "#SBATCH --output=" << (abs / "slurm" / "%A_%a.out").string() << "\n";
  if (!options.partition.empty()) out << "#SBATCH --partition=" << options.partition << "\n";
  if (!options.time.empty()) out << "#SBATCH --time=" << options.time << "\n";
  out << "exec " << shell_quote(conform.string()) << " sweep --task \"$SLURM_ARRAY_TASK_ID\" "
      << shell_quote(abs.string()) << "\n";
  if (!out) throw std::runtime_error("cannot write " + file.string());
  return file;
}

std::string submit_sbatch(const fs::path& sbatch_file) {
  const std::string cmd = "sbatch --parsable " + shell_quote(sbatch_file.string()) + " 2>&1";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) throw std::runtime_error("cannot run sbatch");
  std::string output;
  char buf[256];
  while (std::fgets(buf, sizeof buf, pipe)) output += buf;
  const int rc = ::pclose(pipe);
  while (!output.empty() && (output.back() == '\n' || output.back() == '\r')) output.pop_back();
  // --parsable prints "JOBID" or "JOBID;CLUSTER".
  const std::string id = output.substr(0, output.find(';'));
  if (rc != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw std::runtime_error("sbatch failed: " + (output.empty() ? "no output" : output));
  return id;
}

}  // namespace conform::scenes
