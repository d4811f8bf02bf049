// Progress on stderr (scenes/base/progress.hpp), through the real `conform`
// command: a run longer than a second shows it, as plain lines (at most one per tenth, the last at
// 100 %) when stderr is a file and as a bar redrawn in place on a terminal (util-linux's
// `script` gives the run a pseudo-terminal); a run shorter than a second shows none.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

fs::path scratch(const std::string& what) {
  return fs::temp_directory_path() /
         ("conform_progress_" + what + "_" + std::to_string(::getpid()));
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

struct RunResult {
  std::string err;    // stderr (with `terminal`: everything the terminal showed)
  double wall_s = 0;  // summary.json's timings.wall_s
};

// `conform run tear-opening` for `steps` steps, without pictures or plots.
RunResult run(int steps, bool terminal) {
  const fs::path out = scratch("out"), err = scratch("err");
  fs::remove_all(out);
  const std::string conform = (fs::path(CONFORM_BINARY_DIR) / "scenes" / "conform").string();
  std::string cmd = conform + " run tear-opening --no-render --set outputs.plots=false --set " +
                    "outputs.frames_every=0 --steps " + std::to_string(steps) + " --out " +
                    out.string();
  // script: the command's stdout and stderr both go to the pseudo-terminal, and from there
  // to script's stdout.
  cmd = terminal ? "script -qfec '" + cmd + "' /dev/null > " + err.string() + " 2>&1"
                 : cmd + " > /dev/null 2> " + err.string();
  EXPECT_EQ(std::system(cmd.c_str()), 0) << cmd;
  RunResult r{read_text(err), 0};
  const std::string summary = read_text(out / "summary.json");
  const auto at = summary.find("\"wall_s\": ");
  if (at != std::string::npos) r.wall_s = std::atof(summary.c_str() + at + 10);
  fs::remove_all(out);
  fs::remove(err);
  return r;
}

std::vector<std::string> lines_with(const std::string& text, const std::string& part) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);)
    if (l.find(part) != std::string::npos) out.push_back(l);
  return out;
}

// Steps that take well over a second: about 1 ms a step on the 2-core machine, 15 ms sanitized.
int long_run() {
  return std::getenv("CONFORM_SANITIZED") ? 400 : 3000;
}

TEST(Progress, LongRunWritesPlainLinesWhenNotOnATerminal) {
  const int steps = long_run();
  const std::string err = run(steps, false).err;
  const auto lines = lines_with(err, "tear-opening: ");
  ASSERT_FALSE(lines.empty()) << err;
  EXPECT_LE(lines.size(), 11u) << err;  // at most one per tenth
  const std::string all = std::to_string(steps);
  EXPECT_NE(lines.back().find("100% (step " + all + " of " + all), std::string::npos) << err;
  EXPECT_EQ(err.find('\r'), std::string::npos) << "no redrawing in a file";
}

TEST(Progress, ShortRunStaysQuiet) {
  const RunResult r = run(60, false);
  // Sanitized builds are many times slower: there even 60 steps may take longer than a second.
  if (r.wall_s >= 0.9) GTEST_SKIP() << "the short run took " << r.wall_s << " s";
  ASSERT_GT(r.wall_s, 0) << r.err;
  EXPECT_TRUE(lines_with(r.err, "% (step").empty()) << r.err;
}

TEST(Progress, OnATerminalABarIsRedrawnInPlace) {
  if (std::system("command -v script > /dev/null 2>&1") != 0) GTEST_SKIP() << "no script(1)";
  const int steps = long_run();
  const std::string out = run(steps, true).err, all = std::to_string(steps);
  EXPECT_NE(out.find("\r\033[Ktear-opening ["), std::string::npos) << out;
  EXPECT_NE(out.find("] 100% (step " + all + " of " + all), std::string::npos) << out;
}

}  // namespace
