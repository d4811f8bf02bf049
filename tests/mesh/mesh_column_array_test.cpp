#include <gtest/gtest.h>

#include "conform/mesh/column_array.hpp"

using conform::mesh::ColumnArray;

// Growth keeps every used column, reallocates O(log n) times (not once per append), and copies,
// moves and assignments behave as Eigen matrices do.
TEST(ColumnArray, GrowsGeometricallyAndKeepsColumns) {
  ColumnArray<double, 3> a;
  EXPECT_EQ(a.cols(), 0);
  EXPECT_EQ(a.capacity(), 0);
  int reallocations = 0;
  const double* data = nullptr;
  for (int n = 1; n <= 10000; ++n) {
    a.conservativeResize(3, n);
    a.col(n - 1) = Eigen::Vector3d(n, -n, 0.5 * n);
    if (a.data() != data) ++reallocations, data = a.data();
  }
  EXPECT_LT(reallocations, 30);
  EXPECT_GE(a.capacity(), a.cols());
  for (int n = 1; n <= 10000; ++n) ASSERT_EQ(a.col(n - 1), Eigen::Vector3d(n, -n, 0.5 * n)) << n;
}

TEST(ColumnArray, CopyMoveAndAssignAsAMatrix) {
  const Eigen::Matrix3Xd m = Eigen::Matrix3Xd::Random(3, 57);
  ColumnArray<double, 3> a = m;
  EXPECT_EQ(Eigen::Matrix3Xd(a), m);
  EXPECT_GT(a.capacity(), a.cols());  // room for the first changes
  ColumnArray<double, 3> b = a;
  b(0, 0) = 42;
  EXPECT_EQ(a(0, 0), m(0, 0));  // a copy owns its storage
  ColumnArray<double, 3> c = std::move(b);
  EXPECT_EQ(c(0, 0), 42);
  EXPECT_EQ(b.cols(), 0);
  c = a;
  EXPECT_EQ(Eigen::Matrix3Xd(c), m);
  c = 2 * c;  // the right side reads the array it is assigned to
  EXPECT_EQ(Eigen::Matrix3Xd(c), 2 * m);
  c = m.leftCols(5);  // assignment changes the size
  EXPECT_EQ(c.cols(), 5);
  EXPECT_EQ(Eigen::Matrix3Xd(c), m.leftCols(5));
  ColumnArray<std::int32_t, 4> z;
  z.setZero(4, 9);
  EXPECT_EQ(z.cols(), 9);
  EXPECT_EQ(z.cwiseAbs().sum(), 0);
  EXPECT_THROW(z.resize(3, 9), std::invalid_argument);  // the row count is fixed
  EXPECT_THROW(a = Eigen::MatrixXd::Zero(2, 4), std::invalid_argument);
  EXPECT_EQ(Eigen::Matrix3Xd(a), m);  // a failed assignment leaves the array as it was
}
