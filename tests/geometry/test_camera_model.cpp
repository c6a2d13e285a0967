// SPDX-License-Identifier: MIT
// CameraModel: projection against OpenCV, undistortion round trips at the corners, scaling, size checks (eq. 24, the
// thesis's ray: tests/localizer/test_sphere_localizer.cpp).
#include "geometry_reference.hpp"

#include <gtest/gtest.h>
#include <wingman/geometry/camera_model.hpp>

#include <random>
#include <stdexcept>

namespace wingman::geometry {
namespace {

using testing::test_cameras;

TEST(CameraModel, RejectsBadParametersNamingThem) {
  auto message = [](auto&& make) -> std::string {
    try {
      make();
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "(no error)";
  };
  EXPECT_NE(message([] { CameraModel::pinhole(0, 720, 640, 640, 640, 360); }).find("0x720"), std::string::npos);
  EXPECT_NE(message([] { CameraModel::pinhole(1280, 720, -1, 640, 640, 360); }).find("fx = -1"), std::string::npos);
  EXPECT_NE(message([] { CameraModel::pinhole(1280, 720, 640, NAN, 640, 360); }).find("fy = nan"), std::string::npos);
  EXPECT_NE(message([] {
              CameraModel(1280, 720, 640, 640, 640, 360, Distortion::kEquidistant, {0.1});
            }).find("equidistant distortion needs 4 coefficients"),
            std::string::npos);
  EXPECT_NE(message([] {
              CameraModel(1280, 720, 640, 640, 640, 360, Distortion::kRationalPolynomial, {0, 0, 0, 0, 0});
            }).find("got 5"),
            std::string::npos);
}

TEST(CameraModel, PlumbBobWithFourCoefficientsGetsZeroK3) {
  const CameraModel c(640, 480, 500, 500, 320, 240, Distortion::kRadTan, {0.1, -0.2, 0.001, 0.002});
  ASSERT_EQ(c.coefficients().size(), 5u);
  EXPECT_EQ(c.coefficients()[4], 0.0);
  EXPECT_EQ(c.model_name(), "plumb_bob");
}

TEST(CameraModel, ProjectMatchesOpenCvForEveryModel) {
  std::mt19937 rng(7);
  for (const auto& [label, camera] : test_cameras()) {
    std::uniform_real_distribution<double> angle(-1.0, 1.0);  // tan of up to 45 degrees per axis
    std::vector<cv::Point3d> points;
    std::vector<Eigen::Vector3d> eigen_points;
    for (int i = 0; i < 500; ++i) {
      const double z = std::uniform_real_distribution<double>(0.3, 80)(rng);
      const Eigen::Vector3d p(angle(rng) * z, angle(rng) * 0.7 * z, z);
      eigen_points.push_back(p);
      points.emplace_back(p.x(), p.y(), p.z());
    }
    const std::vector<cv::Point2d> expected = testing::opencv_project(camera, points);
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Eigen::Vector2d uv = camera.project(eigen_points[i]);
      ASSERT_NEAR(uv.x(), expected[i].x, 1e-8) << label << " point " << eigen_points[i].transpose();
      ASSERT_NEAR(uv.y(), expected[i].y, 1e-8) << label << " point " << eigen_points[i].transpose();
    }
  }
}

TEST(CameraModel, UndistortThenDistortRoundTripsAtImageCornersAndEdges) {
  for (const auto& [label, camera] : test_cameras()) {
    const double w = camera.width(), h = camera.height();
    // Corners, edge midpoints, centre and a grid; pixel coordinates span [-0.5, w - 0.5].
    std::vector<Eigen::Vector2d> pixels = {{-0.5, -0.5},  {w - 0.5, -0.5}, {-0.5, h - 0.5}, {w - 0.5, h - 0.5},
                                           {w / 2, -0.5}, {-0.5, h / 2},   {w / 2, h / 2}};
    for (int i = 0; i <= 10; ++i)
      for (int j = 0; j <= 10; ++j) pixels.emplace_back(-0.5 + w * i / 10.0, -0.5 + h * j / 10.0);
    for (const Eigen::Vector2d& uv : pixels) {
      const Eigen::Vector3d ray = camera.unproject(uv);
      if (camera.distortion() == Distortion::kEquidistant) {
        // The fisheye's corners lie beyond 90 degrees, which rays with z > 0 cannot reach: skip beyond 80.
        const double theta = std::hypot((uv.x() - camera.cx()) / camera.fx(), (uv.y() - camera.cy()) / camera.fy());
        if (theta > 80 * M_PI / 180) continue;
      }
      ASSERT_NEAR(ray.norm(), 1.0, 1e-12);
      ASSERT_GT(ray.z(), 0) << label;
      const Eigen::Vector2d back = camera.project(ray);
      EXPECT_NEAR((back - uv).norm(), 0.0, 1e-7) << label << " at pixel " << uv.transpose();
    }
  }
}

TEST(CameraModel, UndistortionIsTighterThanOpenCvsDefaultFiveIterations) {
  // OpenCV's default undistortPoints stops after 5 iterations; at the corner of a distorted lens that leaves a
  // visible error, which the polish removes.
  const CameraModel c = test_cameras()[2].camera;  // rational_polynomial
  const Eigen::Vector2d corner(0, 0);
  std::vector<cv::Point2d> src{{corner.x(), corner.y()}}, dst;
  const cv::Matx33d K(c.fx(), 0, c.cx(), 0, c.fy(), c.cy(), 0, 0, 1);
  cv::undistortPoints(src, dst, K, c.coefficients());
  const Eigen::Vector2d opencv_default(dst[0].x, dst[0].y);
  const double default_error = (c.project(Eigen::Vector3d(opencv_default.x(), opencv_default.y(), 1)) - corner).norm();
  const Eigen::Vector2d ours = c.undistort_to_normalized(corner);
  const double our_error = (c.project(Eigen::Vector3d(ours.x(), ours.y(), 1)) - corner).norm();
  std::printf("corner undistortion error: OpenCV default %.3g px, ours %.3g px\n", default_error, our_error);
  EXPECT_LT(our_error, 1e-8);
}

TEST(CameraModel, ScaledToHalfSizeProjectsToHalfThePixelCoordinates) {
  for (const auto& [label, camera] : test_cameras()) {
    const CameraModel half = camera.scaled_to(camera.width() / 2, camera.height() / 2);
    EXPECT_EQ(half.width(), camera.width() / 2);
    const Eigen::Vector3d p(0.4, -0.2, 3.0);
    const Eigen::Vector2d full = camera.project(p), small = half.project(p);
    // Pixel centres at integers: a pixel edge (u + 0.5) scales by exactly 1/2.
    EXPECT_NEAR(small.x() + 0.5, 0.5 * (full.x() + 0.5), 1e-9) << label;
    EXPECT_NEAR(small.y() + 0.5, 0.5 * (full.y() + 0.5), 1e-9) << label;
    EXPECT_EQ(half.coefficients(), camera.coefficients());
  }
  EXPECT_THROW(test_cameras()[0].camera.scaled_to(0, 10), std::invalid_argument);
}

TEST(CameraModel, CheckImageSizeNamesBothSizes) {
  const CameraModel c = CameraModel::pinhole(1280, 720, 640, 640, 640, 360);
  EXPECT_EQ(c.check_image_size(1280, 720), "");
  const std::string message = c.check_image_size(1280, 960);
  EXPECT_NE(message.find("1280x720"), std::string::npos) << message;
  EXPECT_NE(message.find("1280x960"), std::string::npos) << message;
}

}  // namespace
}  // namespace wingman::geometry
