// `conform ik`: the JSON object has the specified keys, its quaternions are unit and reach the
// target under forward kinematics (v' = q v q*), and bad input fails with a message on stderr.
// Runs the built `conform` command; skipped when it has not been built.
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>

#include "conform/ik/arm_ik.hpp"

namespace {

struct CliRun {
  int code = -1;
  std::string out, err;
};

std::string conform_binary() {
  return std::string(CONFORM_BINARY_DIR) + "/scenes/conform";
}

CliRun run(const std::string& args) {
  const auto dir = std::filesystem::temp_directory_path();
  // ctest runs test cases as parallel processes: name the files by process and call.
  static std::atomic<int> calls{0};
  const std::string tag = std::to_string(::getpid()) + "_" + std::to_string(calls++);
  const auto out = dir / ("conform_ik_out_" + tag), err = dir / ("conform_ik_err_" + tag);
  const std::string cmd =
      conform_binary() + " ik " + args + " >" + out.string() + " 2>" + err.string();
  CliRun r;
  const int status = std::system(cmd.c_str());
  r.code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  const auto slurp = [](const std::filesystem::path& p) {
    std::ifstream f(p);
    std::stringstream s;
    s << f.rdbuf();
    return s.str();
  };
  r.out = slurp(out), r.err = slurp(err);
  std::filesystem::remove(out), std::filesystem::remove(err);
  return r;
}

Eigen::Quaterniond quat(const nlohmann::json& j) {
  return Eigen::Quaterniond(j.at(0).get<double>(), j.at(1).get<double>(), j.at(2).get<double>(),
                            j.at(3).get<double>());
}

class IkCli : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!std::filesystem::exists(conform_binary())) GTEST_SKIP() << "conform not built";
  }
};

}  // namespace

TEST_F(IkCli, JsonReachesTheTarget) {
  const CliRun r = run("--target 0.3 0.2 -0.1 --swivel 0.5 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  for (const char* key : {"qs", "qe", "elbow", "status", "wrist_error"})
    EXPECT_TRUE(j.contains(key)) << key;
  EXPECT_EQ(j["status"], "ok");
  const Eigen::Quaterniond qs = quat(j["qs"]), qe = quat(j["qe"]);
  EXPECT_NEAR(qs.norm(), 1, 1e-12);
  EXPECT_NEAR(qe.norm(), 1, 1e-12);
  // The default arm is 0.30 / 0.25; FK with the printed quaternions lands on the target.
  const conform::ik::Arm<double> arm;
  const auto fk = conform::ik::forward_kinematics(arm, qs, qe);
  EXPECT_LT((fk.wrist - Eigen::Vector3d(0.3, 0.2, -0.1)).norm(), 1e-12);
  const Eigen::Vector3d elbow(j["elbow"][0], j["elbow"][1], j["elbow"][2]);
  EXPECT_LT((fk.elbow - elbow).norm(), 1e-12);
  EXPECT_LT(j["wrist_error"].get<double>(), 1e-12);
  // The same solve as the library's.
  const auto s = conform::ik::solve(arm, Eigen::Vector3d(0.3, 0.2, -0.1), 0.5);
  EXPECT_LT((s.elbow - elbow).norm(), 1e-15);
}

TEST_F(IkCli, LengthsAndClampedTargets) {
  const CliRun r = run("--target 0 0 2 --upper 0.5 --fore 0.4 --json");
  ASSERT_EQ(r.code, 0) << r.err;
  const auto j = nlohmann::json::parse(r.out);
  EXPECT_EQ(j["status"], "clamped_outer|target_on_z_axis|elbow_on_z_axis");
  EXPECT_NEAR(j["wrist_error"].get<double>(), 2 - 0.9, 1e-12);
  EXPECT_NEAR(j["elbow"][2].get<double>(), 0.5, 1e-12);
  const CliRun text = run("--target 0.1 0.2 0.3");
  EXPECT_EQ(text.code, 0);
  EXPECT_NE(text.out.find("status      ok"), std::string::npos) << text.out;
  EXPECT_NE(text.out.find("wrist_error"), std::string::npos);
}

TEST_F(IkCli, BadInputFailsOnStderr) {
  for (const char* args : {"--target 0.1 0.2 0.3 --upper -1", "--target nan 0 0",
                           "--target 0.1 0.2 0.3 --swivel 1e9", "--target 0.1 0.2"}) {
    const CliRun r = run(args);
    EXPECT_NE(r.code, 0) << args;
    EXPECT_FALSE(r.err.empty()) << args;
    EXPECT_TRUE(r.out.empty()) << args;
  }
}
