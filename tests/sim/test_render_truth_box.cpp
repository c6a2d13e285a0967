// SPDX-License-Identifier: MIT
// TruthBoxProjector: the box of the projected vertices, the pixel-corner origin, clipping, what is out of view, and
// where a radtan lens folds back.
#include "test_render_support.hpp"

#include <gtest/gtest.h>
#include <wingman/sim/truth_box.hpp>

#include <limits>

namespace wingman::sim {
namespace {

using test::look_at;

struct Scene {
  geometry::CameraModel camera = test::pinhole();
  DroneModel model = DroneModel::procedural(DroneSpec{});
  Eigen::Isometry3d T_cam_to_world = look_at({0, 0, 10}, {0, 10, 10});
};

Eigen::Isometry3d at(const Eigen::Vector3d& p, double yaw = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = p;
  return T;
}

TEST(TruthBox, IsTheBoxOfTheProjectedVerticesInBoxPixels) {
  Scene s;
  const TruthBoxProjector projector(s.camera);
  const Eigen::Isometry3d T_body = at({0.7, 9.0, 10.4}, 0.4);
  const RenderedBox box = projector.project(s.model, s.T_cam_to_world, T_body, 0.3, 42);
  std::vector<Eigen::Vector3d> points;
  s.model.posed_points(0.3, points);
  double u0 = 1e9, u1 = -1e9, v0 = 1e9, v1 = -1e9;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector2d uv = s.camera.project(s.T_cam_to_world.inverse() * T_body * p);
    u0 = std::min(u0, uv.x());
    u1 = std::max(u1, uv.x());
    v0 = std::min(v0, uv.y());
    v1 = std::max(v1, uv.y());
  }
  EXPECT_TRUE(box.visible);
  EXPECT_FALSE(box.truncated);
  EXPECT_EQ(box.vehicle_id, 42);
  EXPECT_EQ(box.visible_pixels, -1);
  // detections_t convention: the corner of the top-left pixel is 0, so calibration pixel u is box pixel u + 0.5.
  EXPECT_NEAR(box.cx - box.w / 2, u0 + 0.5, 1e-9);
  EXPECT_NEAR(box.cx + box.w / 2, u1 + 0.5, 1e-9);
  EXPECT_NEAR(box.cy - box.h / 2, v0 + 0.5, 1e-9);
  EXPECT_NEAR(box.cy + box.h / 2, v1 + 0.5, 1e-9);
  EXPECT_NEAR(box.range_m, (Eigen::Vector3d(0.7, 9.0, 0.4)).norm(), 1e-9);
}

TEST(TruthBox, PropellerAngleMovesTheBox) {
  Scene s;
  const TruthBoxProjector projector(s.camera);
  const Eigen::Isometry3d T_body = at({0.0, 3.0, 10.0});
  const RenderedBox a = projector.project(s.model, s.T_cam_to_world, T_body, 0.0);
  const RenderedBox b = projector.project(s.model, s.T_cam_to_world, T_body, 0.9);
  EXPECT_GT(std::abs(a.w - b.w) + std::abs(a.h - b.h), 0.5);
}

TEST(TruthBox, IsClippedAtTheImageBorderAndMarkedTruncated) {
  Scene s;
  const TruthBoxProjector projector(s.camera);
  // Centre just left of the image: the right part is in view.
  const Eigen::Vector3d p = test::world_at_pixel(s.camera, s.T_cam_to_world, {-5.0, 360.0}, 5.0);
  const RenderedBox box = projector.project(s.model, s.T_cam_to_world, at(p), 0.0);
  EXPECT_TRUE(box.visible);
  EXPECT_TRUE(box.truncated);
  EXPECT_DOUBLE_EQ(box.cx - box.w / 2, 0.0);
  EXPECT_GT(box.w, 10.0);
  EXPECT_LT(box.cx + box.w / 2, 100.0);
}

TEST(TruthBox, BehindOrBesideTheCameraIsNotVisible) {
  Scene s;
  const TruthBoxProjector projector(s.camera);
  EXPECT_FALSE(projector.project(s.model, s.T_cam_to_world, at({0, -4, 10}), 0.0).visible);
  EXPECT_FALSE(projector.project(s.model, s.T_cam_to_world, at({30, 4, 10}), 0.0).visible);
  // Straddling the camera plane, off to the right: reaches the right border.
  const RenderedBox side = projector.project(s.model, s.T_cam_to_world, at({0.3, 0.1, 10}), 0.0);
  EXPECT_TRUE(side.visible);
  EXPECT_TRUE(side.truncated);
  EXPECT_DOUBLE_EQ(side.cx + side.w / 2, s.camera.width());
}

TEST(TruthBox, RadTanFoldBackIsOutsideTheFieldOfView) {
  // The Raspberry Pi v2 lens: r_d = r (1 + k1 r^2 + k2 r^4) stops growing at r ~ 1.0 and folds back into the image
  // beyond it (r = 1.5 lands on the other side of the centre).
  const geometry::CameraModel camera(1280, 720, 1276.7, 1274.3, 634.9, 379.8, geometry::Distortion::kRadTan,
                                     {0.1465, -0.2847, 0.0013, -0.0043, 0.0});
  const TruthBoxProjector projector(camera);
  const Eigen::Vector3d folded(1.5, 0.0, 1.0);
  ASSERT_GT(camera.project(folded).x(), 0.0);
  ASSERT_LT(camera.project(folded).x(), camera.width()) << "this point would land inside the image";
  EXPECT_FALSE(projector.in_field_of_view(folded));
  EXPECT_TRUE(projector.in_field_of_view({0.5, 0.28, 1.0}));  // the image corner
  const double r_max = projector.max_normalized_radius({1.0, 0.0});
  EXPECT_GT(r_max, 0.95);
  EXPECT_LT(r_max, 1.06);
  // A drone out there is not in the image, even though its vertices would project into it.
  const DroneModel model = DroneModel::procedural(DroneSpec{});
  const RenderedBox box = projector.project(model, Eigen::Isometry3d::Identity(), at(folded * 3.0), 0.0);
  EXPECT_FALSE(box.visible);
}

TEST(TruthBox, FieldOfViewLimitHoldsForFisheyes) {
  const TruthBoxProjector projector(test::fisheye(), 60.0);
  EXPECT_TRUE(projector.in_field_of_view({std::tan(0.99 * 60.0 * M_PI / 180.0), 0.0, 1.0}));
  EXPECT_FALSE(projector.in_field_of_view({std::tan(1.01 * 60.0 * M_PI / 180.0), 0.0, 1.0}));
  EXPECT_FALSE(projector.in_field_of_view({0.0, 0.0, -1.0}));
  EXPECT_THROW(TruthBoxProjector(test::fisheye(), 90.0), std::invalid_argument);
}

}  // namespace
}  // namespace wingman::sim
