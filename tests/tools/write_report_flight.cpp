// SPDX-License-Identifier: MIT
// Test support: writes a small synthetic flight log (fixed seed) for the `wingman report` browser test: ground truth,
// detections (single and zoom-in), targets with a track switch and a false track, and a few BGR8 camera frames.
#include "test_support.hpp"

#include <wingman/detections_t.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/targets_t.hpp>

#include <opencv2/imgproc.hpp>

#include <cmath>
#include <iostream>
#include <random>

using namespace wingman;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: wingman-write-report-flight OUT.lcmlog" << std::endl;
    return 2;
  }
  constexpr int64_t kT0 = 1767225600000000, kWall = 1767300000000000;
  constexpr int kFrames = 120, kWidth = 480, kHeight = 270;
  constexpr double kFocalPx = 300.0, kRadius = 0.348, kPi = 3.14159265358979;
  std::mt19937 rng(42);
  std::normal_distribution<double> unit(0.0, 1.0);
  std::vector<testing::LogEvent> events;
  for (int k = 0; k < kFrames; ++k) {
    const int64_t u = kT0 + k * 100000, wall = kWall + k * 100000;
    const double t = 0.1 * k;
    // The follower creeps north; the leader swings out from 4 m to 36 m ahead and back, drifting east and west.
    const double fy = 0.2 * t, range_ahead = 20.0 - 16.0 * std::cos(2 * kPi * t / 12.0);
    const double lx = 3.0 * std::sin(2 * kPi * t / 6.0), ly = fy + range_ahead, lz = 5.0 + 0.5 * std::sin(t);
    ground_truth_t g{};
    g.utime = u;
    g.image_seq = k;
    for (int id = 0; id < 2; ++id) {
      vehicle_truth_t v{};
      v.vehicle_id = id;
      v.name = id == 0 ? "follower" : "leader";
      v.p_body_in_world[0] = id == 0 ? 0.0 : lx;
      v.p_body_in_world[1] = id == 0 ? fy : ly;
      v.p_body_in_world[2] = id == 0 ? 5.0 : lz;
      v.q_body_to_world[0] = 1.0;
      v.bounding_radius = kRadius;
      g.vehicles.push_back(v);
    }
    g.num_vehicles = 2;
    // Camera looking north from the follower: x right (east), y down, z forward (north).
    const double z = ly - fy, range = std::sqrt(lx * lx + z * z + (lz - 5.0) * (lz - 5.0));
    truth_box_t b{};
    b.vehicle_id = 1;
    b.cx = static_cast<float>(kWidth / 2 + kFocalPx * lx / z);
    b.cy = static_cast<float>(kHeight / 2 - kFocalPx * (lz - 5.0) / z);
    b.w = b.h = static_cast<float>(2 * kFocalPx * kRadius / z);
    b.visible = true;
    b.range = range;
    g.boxes = {b};
    g.num_boxes = 1;
    events.push_back(testing::make_event("GROUND_TRUTH", g, wall));

    if (k % 20 == 0) {  // a camera frame every 2 s: sky, ground, the leader as a dark disc
      cv::Mat img(kHeight, kWidth, CV_8UC3, cv::Scalar(235, 206, 135));
      cv::rectangle(img, cv::Rect(0, kHeight * 2 / 3, kWidth, kHeight / 3), cv::Scalar(60, 140, 80), cv::FILLED);
      cv::circle(img, cv::Point(static_cast<int>(b.cx), static_cast<int>(b.cy)), std::max(2, static_cast<int>(b.w / 2)),
                 cv::Scalar(40, 40, 40), cv::FILLED);
      image_t m{};
      m.utime = u;
      m.seq = k;
      m.width = kWidth;
      m.height = kHeight;
      m.stride = kWidth * 3;
      m.pixel_format = image_t::BGR8;
      m.data.assign(img.data, img.data + img.total() * img.elemSize());
      m.size = static_cast<int32_t>(m.data.size());
      events.push_back(testing::make_event("IMAGE_CAM0", m, wall - 1000));
    }

    detections_t d{};
    d.utime = u;
    d.seq = k;
    d.image_width = kWidth;
    d.image_height = kHeight;
    d.inference_latency_us = static_cast<int32_t>(15000 + 3000 * std::abs(unit(rng)));
    detection_t det{};
    const bool zoom = k % 2 == 1;
    det.cx = static_cast<float>(b.cx + unit(rng));
    det.cy = static_cast<float>(b.cy + unit(rng));
    det.w = det.h = static_cast<float>(std::max(1.0, b.w * (1.0 + (zoom ? 0.03 : 0.1) * unit(rng))));
    det.confidence = 0.8f;
    if (zoom)  // (not a conditional of the two constants: that odr-uses them, and lcm-gen never defines them)
      det.pass_kind = wingman::detection_t::PASS_ZOOM_IN;
    else
      det.pass_kind = wingman::detection_t::PASS_SINGLE;
    d.detections = {det};
    d.num_detections = 1;
    const int64_t latency_us = static_cast<int64_t>(20000 + 4000 * std::abs(unit(rng)));
    events.push_back(testing::make_event("DETECTIONS_CAM0", d, wall + latency_us / 2));

    targets_t ts{};
    ts.utime = u;
    target_t tg{};
    tg.track_id = k < 70 ? 3 : 5;  // one id switch
    const double e = 0.02 * range;
    tg.p_target_in_world[0] = lx + e * unit(rng);
    tg.p_target_in_world[1] = ly + 2 * e * unit(rng);
    tg.p_target_in_world[2] = lz + e * unit(rng);
    tg.world_valid = true;
    tg.range = range;
    tg.confidence = 0.9f;
    tg.source_utime = u;
    tg.predicted_utime = u;
    ts.targets = {tg};
    if (k >= 40 && k < 45) {  // a short false track far from both vehicles
      target_t f = tg;
      f.track_id = 9;
      f.p_target_in_world[0] = lx + 15.0;
      ts.targets.push_back(f);
    }
    ts.num_targets = static_cast<int32_t>(ts.targets.size());
    events.push_back(testing::make_event("TARGETS", ts, wall + latency_us));
  }
  testing::write_log(argv[1], events);
  return 0;
}
