// The job convention (ARCHITECTURE.md, Errors): BatchSolveJob::validate() names the first bad
// input with its value, and run() writes nothing and returns false when it is not empty.
#include <gtest/gtest.h>

#include <cstdint>
#include <string>
#include <vector>

#include "conform/ik/arm_ik.hpp"

using namespace conform;

namespace {

struct Buffers {
  explicit Buffers(std::size_t n)
      : x(n, 0.1),
        y(n, 0.2),
        z(n, 0.3),
        swivel(n, 0.0),
        out(13, std::vector<double>(n, -7)),
        status(n, 0xff) {}
  std::vector<double> x, y, z, swivel;
  std::vector<std::vector<double>> out;
  std::vector<std::uint8_t> status;

  ik::BatchSolveJob<double> job() {
    ik::BatchSolveJob<double> j;
    j.x = x, j.y = y, j.z = z, j.swivel = swivel;
    j.qs_w = out[0], j.qs_x = out[1], j.qs_y = out[2], j.qs_z = out[3];
    j.qe_w = out[4], j.qe_x = out[5];
    j.elbow_x = out[6], j.elbow_y = out[7], j.elbow_z = out[8];
    j.status = status;
    j.threads = 1;
    return j;
  }
};

}  // namespace

TEST(IkBatchValidate, AValidJobRuns) {
  Buffers b(8);
  const auto job = b.job();
  EXPECT_EQ(job.validate(), "");
  EXPECT_TRUE(job.Validate());
  EXPECT_TRUE(job.run());
  EXPECT_NE(b.out[0][0], -7);
}

TEST(IkBatchValidate, NamesTheSpanOfTheWrongSizeAndWritesNothing) {
  Buffers b(8);
  auto job = b.job();
  job.qs_w = std::span<double>(b.out[0]).first(5);
  EXPECT_EQ(job.validate(), "qs_w: size 5, x has 8");
  EXPECT_FALSE(job.Validate());
  EXPECT_FALSE(job.run());
  for (const auto& o : b.out)
    for (const double v : o) EXPECT_EQ(v, -7);
  for (const auto s : b.status) EXPECT_EQ(s, 0xff);
}

TEST(IkBatchValidate, NamesTheArmTheConeAndTheThreads) {
  Buffers b(4);
  auto job = b.job();
  job.arm.upper = -1;
  EXPECT_NE(job.validate().find("arm: lengths -1"), std::string::npos) << job.validate();
  job = b.job();
  job.arm.limits.cone_half_angle = 1.0;
  EXPECT_EQ(job.validate().rfind("arm.limits.cone_half_angle: 1.0", 0), 0u) << job.validate();
  job = b.job();
  job.threads = -2;
  EXPECT_EQ(job.validate(), "threads: -2 (must be >= 0)");
}
