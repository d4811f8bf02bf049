#include "sweep/sweep_slurm.hpp"

#include <cctype>
#include <fstream>

#include "base/child_process.hpp"

namespace conform::scenes {

namespace fs = std::filesystem;

namespace {

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

// A directive of the user's: one line (Slurm reads an #SBATCH line to its end, and a line break
// would start a command of the script), an option, and not the array, which is the sweep's.
void check_line(const std::string& line) {
  const auto bad = [&](const std::string& why) {
    throw SceneError("--sbatch-line", show(Json(line)), why);
  };
  for (char c : line)
    if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f)
      bad("must be one line of printable text (no line break or control character)");
  if (line.empty() || line[0] != '-') bad("must be an sbatch option (e.g. --mem=4G)");
  const std::string name = line.substr(0, line.find_first_of("= "));
  if (name.rfind("-a", 0) == 0 || (name.size() >= 4 && std::string("--array").rfind(name, 0) == 0))
    bad("the array is the sweep's points (--array-limit sets how many run at once)");
}

}  // namespace

std::string shell_quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

void check_slurm_options(const SlurmOptions& options) {
  for (const auto& line : options.lines) check_line(line);
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
  for (const auto& line : options.lines) out << "#SBATCH " << line << "\n";
  out << "exec " << shell_quote(conform.string()) << " sweep --task \"$SLURM_ARRAY_TASK_ID\" "
      << shell_quote(abs.string()) << "\n";
  if (!out) throw std::runtime_error("cannot write " + file.string());
  return file;
}

namespace {

// "0-2,5,7-8" for Slurm's --array.
std::string array_list(const std::vector<int>& indices) {
  std::string list;
  for (std::size_t i = 0; i < indices.size();) {
    std::size_t j = i;
    while (j + 1 < indices.size() && indices[j + 1] == indices[j] + 1) ++j;
    list += (list.empty() ? "" : ",") + std::to_string(indices[i]) +
            (j > i ? "-" + std::to_string(indices[j]) : "");
    i = j + 1;
  }
  return list;
}

}  // namespace

std::string resubmit_command(const fs::path& dir, const std::vector<int>& indices) {
  const fs::path file = fs::absolute(dir).lexically_normal() / "sweep.sbatch";
  std::ifstream in(file);
  if (!in || indices.empty()) return "";
  // The array's %LIMIT, from the #SBATCH lines at the top of the file this sweep wrote.
  std::string line, limit;
  for (int n = 0; n < 100 && std::getline(in, line); ++n)
    if (line.rfind("#SBATCH --array=", 0) == 0 && line.find('%') != std::string::npos)
      limit = line.substr(line.find('%'));
  // sbatch's own --array overrides the file's #SBATCH --array.
  return "sbatch --array=" + array_list(indices) + limit + " " + shell_quote(file.string());
}

std::string submit_sbatch(const fs::path& sbatch_file) {
  const fs::path log = sbatch_file.parent_path() / "slurm" / "submit.log";
  ChildOptions options;
  options.log = log.string();
  ChildProcess sbatch({"sbatch", "--parsable", sbatch_file.string()}, options);
  if (!sbatch.running()) throw std::runtime_error(sbatch.error());
  const int rc = sbatch.wait();
  if (rc == 127)
    throw std::runtime_error("sbatch failed: sbatch is not installed (or not on PATH)");
  std::ifstream in(log);
  std::string line, output, id;
  for (int n = 0; n < 1000 && std::getline(in, line); ++n) {
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.empty()) continue;
    output += (output.empty() ? "" : "\n") + line;
    // --parsable prints "JOBID" or "JOBID;CLUSTER", after any warnings.
    id = line.substr(0, line.find(';'));
  }
  if (rc != 0 || id.empty() || id.find_first_not_of("0123456789") != std::string::npos)
    throw std::runtime_error("sbatch failed: " + (output.empty() ? "no output" : output) + " (" +
                             log.string() + ")");
  return id;
}

}  // namespace conform::scenes
