// SPDX-License-Identifier: MIT
// Determinism: the same inputs and frame seed give the same bytes, in one renderer, in two, and in processes with
// different llvmpipe thread counts.
#include "test_render_support.hpp"

#include <gtest/gtest.h>
#include <wingman/sim/renderer.hpp>

#include <opencv2/core.hpp>

#include <fstream>
#include <iterator>

namespace wingman::sim {
namespace {

std::vector<DroneInstance> two_drones(const DroneModel& quad, const DroneModel& disc_hex) {
  std::vector<DroneInstance> drones(2);
  drones[0].vehicle_id = 1;
  drones[0].model = &quad;
  drones[0].T_body_to_world.translation() = Eigen::Vector3d(-1.0, 8.0, 10.3);
  drones[0].prop_angle_rad = 0.4;
  drones[1].vehicle_id = 2;
  drones[1].model = &disc_hex;
  drones[1].T_body_to_world.translation() = Eigen::Vector3d(2.0, 14.0, 11.0);
  return drones;
}

bool same(const cv::Mat& a, const cv::Mat& b) {
  return a.size() == b.size() && a.type() == b.type() && cv::norm(a, b, cv::NORM_INF) == 0.0;
}

TEST(RendererDeterminism, SameSeedSamePixelsInOneRendererAndInTwo) {
  RenderOptions options;  // the default scene with sensor noise
  options.exposure_jitter = 0.2;
  const geometry::CameraModel camera = test::strong_radtan();
  Renderer first(camera, options);
  const DroneModel quad = DroneModel::procedural(DroneSpec{});
  DroneSpec hex;
  hex.frame = "hex";
  hex.prop_style = "disc";
  const DroneModel disc_hex = DroneModel::procedural(hex);
  const auto drones = two_drones(quad, disc_hex);
  const Eigen::Isometry3d T_cam_to_world = test::look_at({0, 0, 10}, {0, 50, 12});
  const RenderResult a = first.render(T_cam_to_world, drones, 123456, 77);
  const RenderResult b = first.render(T_cam_to_world, drones, 123456, 77);
  EXPECT_TRUE(same(a.bgr, b.bgr));
  EXPECT_TRUE(same(a.mask, b.mask));
  Renderer second(camera, options);
  const RenderResult c = second.render(T_cam_to_world, drones, 123456, 77);
  EXPECT_TRUE(same(a.bgr, c.bgr));
  EXPECT_TRUE(same(a.mask, c.mask));
  EXPECT_EQ(a.exposure_gain, c.exposure_gain);
  // Another frame seed: other noise and exposure, the same scene.
  const RenderResult d = first.render(T_cam_to_world, drones, 123456, 78);
  EXPECT_FALSE(same(a.bgr, d.bgr));
  EXPECT_TRUE(same(a.mask, d.mask));
  EXPECT_NE(a.exposure_gain, d.exposure_gain);
  // Another scene seed: other clouds and fields.
  options.seed = 2;
  Renderer other_scene(camera, options);
  const RenderResult e = other_scene.render(T_cam_to_world, drones, 123456, 77);
  cv::Mat diff;
  cv::absdiff(a.bgr, e.bgr, diff);
  EXPECT_GT(cv::mean(diff)[1], 3.0);
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(RendererDeterminism, IdenticalAcrossLlvmpipeThreadCounts) {
  const std::string dump = WINGMAN_RENDER_DUMP_EXE;
  wingman::testing::TempDir dir;
  std::vector<std::string> plain, blur;
  for (const char* threads : {"0", "1", "2", "3"}) {
    const std::string prefix = dir.file(std::string("threads") + threads);
    const auto r = wingman::testing::run({"/usr/bin/env", std::string("LP_NUM_THREADS=") + threads, dump, prefix},
                                         std::chrono::seconds(60));
    ASSERT_EQ(r.exit_code, 0) << "LP_NUM_THREADS=" << threads << ": " << r.err;
    plain.push_back(read_file(prefix + "_plain.png"));
    blur.push_back(read_file(prefix + "_blur.png"));
    ASSERT_GT(plain.back().size(), 100000u);
  }
  for (size_t k = 1; k < plain.size(); ++k) {
    EXPECT_TRUE(plain[k] == plain[0]) << "plain frame differs between LP_NUM_THREADS=0 and run " << k;
    EXPECT_TRUE(blur[k] == blur[0]) << "motion-blurred frame differs between LP_NUM_THREADS=0 and run " << k;
  }
  EXPECT_FALSE(plain[0] == blur[0]);
}

}  // namespace
}  // namespace wingman::sim
