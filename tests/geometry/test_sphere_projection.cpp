// SPDX-License-Identifier: MIT
// The forward model: the exact box of a sphere's image against an independent OpenCV projection, and its refusals.
#include "geometry_reference.hpp"

#include <gtest/gtest.h>
#include <wingman/geometry/sphere_projection.hpp>

namespace wingman::geometry {
namespace {

using testing::reference_sphere_box;
using testing::test_cameras;

constexpr double kRadius = 0.348;  // DJI F450, the localizer's default

TEST(SphereProjection, MatchesTheIndependentOpenCvProjectionForEveryModel) {
  for (const auto& [label, camera] : test_cameras()) {
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(0, 0, 5), Eigen::Vector3d(1.2, -0.5, 2.0),
                                     Eigen::Vector3d(-0.9, 0.6, 1.5), Eigen::Vector3d(4, 2, 6)}) {
      const SphereImageBox box = project_sphere(camera, p, kRadius);
      ASSERT_TRUE(box.valid) << label << ": " << box.reason;
      const testing::ReferenceBox ref = reference_sphere_box(camera, p, kRadius, 40000);
      EXPECT_NEAR(box.u_min, ref.u_min, 1e-4) << label << " at " << p.transpose();
      EXPECT_NEAR(box.u_max, ref.u_max, 1e-4) << label << " at " << p.transpose();
      EXPECT_NEAR(box.v_min, ref.v_min, 1e-4) << label << " at " << p.transpose();
      EXPECT_NEAR(box.v_max, ref.v_max, 1e-4) << label << " at " << p.transpose();
    }
  }
}

TEST(SphereProjection, RejectsASphereAroundOrBehindTheCamera) {
  const CameraModel c = test_cameras()[0].camera;
  EXPECT_FALSE(project_sphere(c, Eigen::Vector3d(0, 0, 0.3), kRadius).valid);
  EXPECT_FALSE(project_sphere(c, Eigen::Vector3d(5, 0, 0.1), kRadius).valid);
  EXPECT_FALSE(project_sphere(c, Eigen::Vector3d(0, 0, -5), kRadius).valid);
}

}  // namespace
}  // namespace wingman::geometry
