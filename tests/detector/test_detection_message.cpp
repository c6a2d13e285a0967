// SPDX-License-Identifier: MIT
// to_detection: a detector Box becomes the detection_t wingman-detector publishes, class and drone score included.
#include <gtest/gtest.h>
#include <wingman/detector/detection_message.hpp>

namespace {

using wingman::detector::Box;
using wingman::detector::to_detection;

TEST(DetectionMessage, CarriesTheClassAndTheDroneScoreOfADistractor) {
  Box bird;
  bird.cx = 100.5f;
  bird.cy = 50.25f;
  bird.w = 12.0f;
  bird.h = 8.0f;
  bird.confidence = 0.8f;  // objectness x P(bird)
  bird.class_id = 2;
  bird.drone_score = 0.1f;  // objectness x P(drone)
  bird.pass = wingman::detector::Pass::kWindow;
  const wingman::detection_t d = to_detection(bird);
  EXPECT_EQ(d.cx, 100.5f);
  EXPECT_EQ(d.cy, 50.25f);
  EXPECT_EQ(d.w, 12.0f);
  EXPECT_EQ(d.h, 8.0f);
  EXPECT_EQ(d.confidence, 0.8f);
  EXPECT_EQ(d.class_id, 2);
  EXPECT_EQ(d.drone_score, 0.1f);
  EXPECT_EQ(int{d.pass_kind}, int{wingman::detection_t::PASS_WINDOW});  // int{}: no odr-use of the constant
}

TEST(DetectionMessage, ADroneKeepsClassZeroAndItsScore) {
  Box drone;
  drone.cx = 640.0f;
  drone.cy = 360.0f;
  drone.w = 40.0f;
  drone.h = 30.0f;
  drone.confidence = 0.9f;
  drone.drone_score = 0.9f;  // equals confidence for class 0
  const wingman::detection_t d = to_detection(drone);
  EXPECT_EQ(d.class_id, 0);
  EXPECT_EQ(d.drone_score, 0.9f);
  EXPECT_EQ(int{d.pass_kind}, int{wingman::detection_t::PASS_SINGLE});
}

}  // namespace
