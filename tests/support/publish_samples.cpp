// SPDX-License-Identifier: MIT
// wingman-publish-samples: publishes (or logs) one valid sample of every message type on its pipeline channel, and the
// camera's monitoring preview (PREVIEW_CAM0, made by camera_driver::PreviewMaker from the sample image).
#include "wingman/common/message_validation.hpp"
#include "wingman/common/time.hpp"

#include <wingman/camera_driver/preview.hpp>

#include <fmt/format.h>
#include <CLI/CLI.hpp>
#include <lcm/lcm-cpp.hpp>
#include <wingman/channel_stats_t.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>

#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

/// Options of wingman-publish-samples.
struct PublishSamplesOptions {
  std::string lcm_url;   ///< bus to publish on; "" = LCM_DEFAULT_URL or LCM's default
  std::string log_path;  ///< write the samples to this LCM log instead of publishing; "" = publish
  int repeat = 1;        ///< rounds; each round has one message per channel
  int period_ms = 100;   ///< milliseconds between rounds (wall clock when publishing, log time when logging)

  /// "" or one line naming the bad option.
  std::string validate() const {
    if (repeat < 1) return fmt::format("--repeat = {}: must be >= 1", repeat);
    if (period_ms < 0) return fmt::format("--period-ms = {}: must be >= 0", period_ms);
    if (!lcm_url.empty() && !log_path.empty()) return "--lcm-url and --log: give at most one of them";
    return "";
  }
};

/// One encoded message and the channel it goes on.
struct Sample {
  std::string channel;
  std::string type;
  std::vector<uint8_t> bytes;
};

/// Checks `msg` with validate_message and encodes it; throws naming the channel if it is not valid.
template <class Msg>
Sample encode_sample(const std::string& channel, const Msg& msg) {
  if (const std::string err = wingman::common::validate_message(msg); !err.empty()) {
    throw std::logic_error(fmt::format("sample on {} is not valid: {}", channel, err));
  }
  Sample s{channel, Msg::getTypeName(), std::vector<uint8_t>(static_cast<size_t>(msg.getEncodedSize()))};
  if (msg.encode(s.bytes.data(), 0, static_cast<int>(s.bytes.size())) < 0) {
    throw std::logic_error(fmt::format("sample on {} does not encode", channel));
  }
  return s;
}

/// Unit quaternion (w, x, y, z) of a rotation by `yaw` radians about the world z axis.
void yaw_quaternion(double yaw, double (&q)[4]) {
  q[0] = std::cos(yaw / 2);
  q[1] = 0;
  q[2] = 0;
  q[3] = std::sin(yaw / 2);
}

void set3(double (&v)[3], double x, double y, double z) {
  v[0] = x;
  v[1] = y;
  v[2] = z;
}

void diag3(double (&m)[9], double d) {
  for (int i = 0; i < 9; ++i) m[i] = (i % 4 == 0) ? d : 0.0;
}

/// The seven samples of round `seq` at time `utime` (microseconds since epoch): one camera frame
/// with a leader drone 12 m ahead of the follower, and what each pipeline stage would make of it.
std::vector<Sample> make_samples(int64_t utime, int64_t seq) {
  constexpr int kWidth = 64;
  constexpr int kHeight = 48;
  constexpr float kBoxCx = 40.5f, kBoxCy = 20.5f, kBoxW = 9.0f, kBoxH = 5.0f;  // pixels
  std::vector<Sample> out;

  wingman::image_t image;
  image.utime = utime;
  image.seq = seq;
  image.camera_id = 0;
  image.width = kWidth;
  image.height = kHeight;
  image.stride = kWidth * 3;
  image.pixel_format = wingman::image_t::BGR8;
  image.data.resize(static_cast<size_t>(image.stride) * kHeight);
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      uint8_t* px = &image.data[static_cast<size_t>(y) * image.stride + 3 * x];
      const bool in_box = std::abs(x + 0.5f - kBoxCx) <= kBoxW / 2 && std::abs(y + 0.5f - kBoxCy) <= kBoxH / 2;
      // Sky gradient (lighter towards the horizon), a dark drone inside the box.
      px[0] = in_box ? 30 : static_cast<uint8_t>(200 + y);  // B
      px[1] = in_box ? 30 : static_cast<uint8_t>(150 + y);  // G
      px[2] = in_box ? 30 : static_cast<uint8_t>(100 + y);  // R
    }
  }
  image.size = static_cast<int32_t>(image.data.size());
  out.push_back(encode_sample("IMAGE_CAM0", image));
  {
    wingman::camera_driver::PreviewMaker preview{wingman::camera_driver::PreviewOptions{}};
    const auto p = preview.offer(image);
    if (!p) throw std::logic_error("the sample image gives no preview");
    out.push_back(encode_sample("PREVIEW_CAM0", *p));
  }

  wingman::detections_t detections;
  detections.utime = utime;
  detections.seq = seq;
  detections.camera_id = 0;
  detections.image_width = kWidth;
  detections.image_height = kHeight;
  detections.inference_latency_us = 8500;
  detections.source = wingman::detections_t::SOURCE_CNN;
  wingman::detection_t d;
  d.cx = kBoxCx;
  d.cy = kBoxCy;
  d.w = kBoxW;
  d.h = kBoxH;
  d.confidence = 0.87f;
  d.class_id = 0;
  d.pass_kind = wingman::detection_t::PASS_SINGLE;
  d.drone_score = 0.87f;  // a drone: the same as confidence
  detections.detections.push_back(d);
  detections.num_detections = static_cast<int32_t>(detections.detections.size());
  out.push_back(encode_sample("DETECTIONS_CAM0", detections));

  // Follower at 10 m altitude heading north (ENU yaw = +90°), flying north at 2 m/s.
  wingman::own_pose_t pose{};
  pose.utime = utime;
  pose.frame = wingman::own_pose_t::FRAME_ENU;
  set3(pose.p_body_in_world, 0.0, 0.0, 10.0);
  yaw_quaternion(M_PI / 2, pose.q_body_to_world);
  set3(pose.v_body_in_world, 0.0, 2.0, 0.0);
  out.push_back(encode_sample("OWN_POSE", pose));

  // Leader 12 m ahead (camera z forward), 1.5 m right, 0.5 m higher; flying alongside.
  wingman::targets_t targets;
  targets.utime = utime;
  targets.frame = wingman::own_pose_t::FRAME_ENU;
  wingman::target_t t;
  t.track_id = 1;
  t.camera_id = 0;
  set3(t.p_target_in_cam, 1.5, -0.5, 12.0);
  set3(t.p_target_in_world, 1.5, 12.0, 10.5);
  set3(t.v_target_in_world, 0.0, 2.0, 0.0);
  diag3(t.position_covariance, 0.25);
  diag3(t.velocity_covariance, 0.04);
  t.range = std::sqrt(1.5 * 1.5 + 0.5 * 0.5 + 12.0 * 12.0);
  t.world_valid = true;
  t.confidence = 0.9f;
  t.age_s = 4.5f;
  t.source_utime = utime;
  t.predicted_utime = utime + 20000;
  t.detection_source = wingman::detections_t::SOURCE_CNN;
  targets.targets.push_back(t);
  targets.num_targets = static_cast<int32_t>(targets.targets.size());
  out.push_back(encode_sample("TARGETS", targets));

  // Keep 5 m behind the leader, facing it.
  wingman::setpoint_t setpoint;
  setpoint.utime = utime;
  setpoint.mode = wingman::setpoint_t::MODE_POSITION;
  setpoint.frame = wingman::own_pose_t::FRAME_ENU;
  set3(setpoint.position, 1.5, 7.0, 10.5);
  set3(setpoint.velocity, 0.0, 0.0, 0.0);
  setpoint.yaw = M_PI / 2;
  setpoint.yaw_rate = 0.0;
  setpoint.target_track_id = 1;
  setpoint.detection_source = wingman::detections_t::SOURCE_CNN;
  out.push_back(encode_sample("SETPOINT", setpoint));

  wingman::status_t status;
  status.utime = utime;
  status.process = "sample";
  status.pid = static_cast<int32_t>(::getpid());
  status.state = wingman::status_t::STATE_OK;
  status.detail = "publishing samples";
  status.uptime_us = seq * 100000;
  status.last_input_utime = utime;
  status.last_processed_seq = seq;
  status.messages_handled = seq + 1;
  status.drops_total = 0;
  status.latency_p50_ms = 8.5f;
  status.latency_p90_ms = 9.7f;
  status.latency_p99_ms = 12.1f;
  status.latency_max_ms = 14.0f;
  status.last_error = "";
  wingman::channel_stats_t stats;
  stats.channel = "IMAGE_CAM0";
  stats.direction = wingman::channel_stats_t::DIRECTION_IN;
  stats.count = seq + 1;
  stats.drops = 0;
  stats.rate_hz = 10.0f;
  stats.last_utime = utime;
  status.channels.push_back(stats);
  status.num_channels = static_cast<int32_t>(status.channels.size());
  out.push_back(encode_sample("STATUS_SAMPLE", status));

  wingman::ground_truth_t truth;
  truth.utime = utime;
  truth.frame = wingman::own_pose_t::FRAME_ENU;
  truth.image_seq = seq;
  wingman::vehicle_truth_t follower;
  follower.vehicle_id = 0;
  follower.name = "follower";
  set3(follower.p_body_in_world, 0.0, 0.0, 10.0);
  yaw_quaternion(M_PI / 2, follower.q_body_to_world);
  set3(follower.v_body_in_world, 0.0, 2.0, 0.0);
  set3(follower.w_body_in_body, 0.0, 0.0, 0.0);
  follower.bounding_radius = 0.4;
  wingman::vehicle_truth_t leader = follower;
  leader.vehicle_id = 1;
  leader.name = "leader";
  set3(leader.p_body_in_world, 1.5, 12.0, 10.5);
  truth.vehicles = {follower, leader};
  truth.num_vehicles = static_cast<int32_t>(truth.vehicles.size());
  wingman::truth_box_t box;
  box.vehicle_id = 1;
  box.camera_id = 0;
  box.cx = kBoxCx;
  box.cy = kBoxCy;
  box.w = kBoxW;
  box.h = kBoxH;
  box.visible = true;
  box.range = t.range;
  truth.boxes.push_back(box);
  truth.num_boxes = static_cast<int32_t>(truth.boxes.size());
  out.push_back(encode_sample("GROUND_TRUTH", truth));

  return out;
}

int run(const PublishSamplesOptions& options) {
  const int64_t start_utime = wingman::common::wall_utime();
  const int64_t period_us = static_cast<int64_t>(options.period_ms) * 1000;

  if (!options.log_path.empty()) {
    lcm::LogFile log(options.log_path, "w");
    if (!log.good()) throw std::runtime_error(fmt::format("cannot open LCM log for writing: {}", options.log_path));
    int64_t eventnum = 0;
    for (int round = 0; round < options.repeat; ++round) {
      const int64_t utime = start_utime + round * period_us;
      for (const Sample& s : make_samples(utime, round)) {
        lcm::LogEvent ev;
        ev.eventnum = eventnum++;
        ev.timestamp = utime;
        ev.channel = s.channel;
        ev.datalen = static_cast<int32_t>(s.bytes.size());
        ev.data = const_cast<uint8_t*>(s.bytes.data());
        if (log.writeEvent(&ev) != 0) throw std::runtime_error(fmt::format("cannot write to {}", options.log_path));
      }
    }
    std::cerr << fmt::format("wingman-publish-samples: wrote {} rounds of 8 channels to {}\n", options.repeat,
                             options.log_path);
    return 0;
  }

  lcm::LCM lcm(options.lcm_url);
  if (!lcm.good()) {
    throw std::runtime_error(
        fmt::format("cannot open LCM URL '{}'", options.lcm_url.empty() ? "(default)" : options.lcm_url));
  }
  for (int round = 0; round < options.repeat; ++round) {
    if (round > 0 && options.period_ms > 0) std::this_thread::sleep_for(std::chrono::milliseconds(options.period_ms));
    for (const Sample& s : make_samples(wingman::common::wall_utime(), round)) {
      if (lcm.publish(s.channel, s.bytes.data(), static_cast<unsigned>(s.bytes.size())) != 0) {
        throw std::runtime_error(fmt::format("cannot publish {} on {}", s.type, s.channel));
      }
    }
  }
  std::cerr << fmt::format("wingman-publish-samples: published {} rounds of 7 channels\n", options.repeat);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  PublishSamplesOptions options;
  CLI::App app{"Publish one valid sample of every Wingman message type on its pipeline channel",
               "wingman-publish-samples"};
  app.add_option("--lcm-url", options.lcm_url, "LCM URL to publish on (default: LCM_DEFAULT_URL)");
  app.add_option("--log", options.log_path, "Write the samples to this LCM log instead of publishing");
  app.add_option("--repeat", options.repeat, "Rounds of samples (one message per channel each)");
  app.add_option("--period-ms", options.period_ms, "Milliseconds between rounds");
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() != 0) {
      std::cerr << "wingman-publish-samples: error: " << e.what() << " (see --help)" << std::endl;
      return 2;
    }
    return app.exit(e);
  }
  if (const std::string err = options.validate(); !err.empty()) {
    std::cerr << "wingman-publish-samples: error: " << err << std::endl;
    return 2;
  }
  try {
    return run(options);
  } catch (const std::exception& e) {
    std::cerr << "wingman-publish-samples: error: " << e.what() << std::endl;
    return 1;
  }
}
