// SPDX-License-Identifier: MIT
// The message-array <-> Eigen copies: element order (x y z; w x y z; row-major; upper triangle row by row) and exact
// round trips.
#include <gtest/gtest.h>
#include <wingman/geometry/message_eigen.hpp>

namespace wingman::geometry {
namespace {

TEST(MessageEigen, VectorsKeepTheOrderXYZ) {
  const double a[3] = {1.5, -2.25, 3e-300};
  const Eigen::Vector3d v = to_vector3(a);
  EXPECT_EQ(v, Eigen::Vector3d(1.5, -2.25, 3e-300));
  double back[3] = {0, 0, 0};
  to_array(v, back);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(back[i], a[i]) << "i = " << i;
}

TEST(MessageEigen, QuaternionsAreWXYZAndNotNormalized) {
  const double q[4] = {2.0, 0.5, -0.25, 0.125};  // norm != 1 on purpose: copied as it is
  const Eigen::Quaterniond e = to_quaternion(q);
  EXPECT_EQ(e.w(), 2.0);
  EXPECT_EQ(e.x(), 0.5);
  EXPECT_EQ(e.y(), -0.25);
  EXPECT_EQ(e.z(), 0.125);
  double back[4] = {0, 0, 0, 0};
  to_array(e, back);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(back[i], q[i]) << "i = " << i;
}

TEST(MessageEigen, MatricesAreRowMajor) {
  const double a[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  const Eigen::Matrix3d m = to_matrix3(a);
  EXPECT_EQ(m(0, 1), 2.0);  // row 0, column 1
  EXPECT_EQ(m(1, 0), 4.0);
  EXPECT_EQ(m(2, 1), 8.0);
  double back[9] = {};
  to_array(m, back);
  for (int i = 0; i < 9; ++i) EXPECT_EQ(back[i], a[i]) << "i = " << i;
}

TEST(MessageEigen, UpperTriangleIsRowByRowAndMirrored) {
  const double a[6] = {1, 2, 3, 4, 5, 6};  // xx xy xz yy yz zz
  const Eigen::Matrix3d m = from_upper_triangle(a);
  Eigen::Matrix3d expected;
  expected << 1, 2, 3,  //
      2, 4, 5,          //
      3, 5, 6;
  EXPECT_EQ(m, expected);
  double back[6] = {};
  to_upper_triangle(m, back);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(back[i], a[i]) << "i = " << i;
  // The lower triangle is not read.
  Eigen::Matrix3d upper_only = expected.triangularView<Eigen::Upper>();
  to_upper_triangle(upper_only, back);
  for (int i = 0; i < 6; ++i) EXPECT_EQ(back[i], a[i]) << "i = " << i;
}

}  // namespace
}  // namespace wingman::geometry
