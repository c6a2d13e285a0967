// SPDX-License-Identifier: MIT
// Writes the generated part of the seed corpus (tests/fuzz/corpus/<target>/): valid messages of every type in the
// record layout of fuzz_support.hpp, and a tiny .weights file. Usage: make_seeds CORPUS_DIR. The file-format seeds
// (configs, calibrations, cfgs, scenarios) are copies of the repository's own files (tests/fuzz/README.md).
#include "tiny_model.hpp"

#include <wingman/detections_t.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/ground_truth_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/mavlink/enums.hpp>
#include <wingman/mavlink/frame.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>

#include <opencv2/imgcodecs.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace {

using namespace wingman;
namespace fs = std::filesystem;
using Bytes = std::vector<uint8_t>;

template <class Msg>
Bytes encode(const Msg& m) {
  Bytes b(static_cast<size_t>(m.getEncodedSize()));
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

/// One record: selector, 2-byte big-endian length, payload.
Bytes record(uint8_t selector, const Bytes& payload) {
  Bytes r{selector, static_cast<uint8_t>(payload.size() >> 8), static_cast<uint8_t>(payload.size() & 0xff)};
  r.insert(r.end(), payload.begin(), payload.end());
  return r;
}

Bytes cat(std::initializer_list<Bytes> parts) {
  Bytes all;
  for (const auto& p : parts) all.insert(all.end(), p.begin(), p.end());
  return all;
}

Bytes prefixed(uint8_t first, const Bytes& rest) { return cat({Bytes{first}, rest}); }

void save(const fs::path& dir, const std::string& name, const Bytes& bytes) {
  fs::create_directories(dir);
  std::ofstream out(dir / name, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  std::printf("%s (%zu bytes)\n", (dir / name).c_str(), bytes.size());
}

Bytes text(const std::string& s) { return Bytes(s.begin(), s.end()); }

image_t image(int8_t format, int w, int h) {
  image_t m{};
  m.utime = 1700000000000000;
  m.seq = 7;
  m.width = w;
  m.height = h;
  m.pixel_format = format;
  const int bpp = format == image_t::GRAY8 ? 1 : format == image_t::BGR8 ? 3 : 2;
  if (format == image_t::MJPEG) {
    std::vector<uint8_t> jpeg;
    cv::imencode(".jpg", cv::Mat(h, w, CV_8UC3, cv::Scalar(40, 80, 120)), jpeg);
    m.data = jpeg;
    m.stride = 0;
  } else {
    m.stride = w * bpp;
    m.data.assign(static_cast<size_t>(m.stride) * static_cast<size_t>(h), 0);
    for (size_t i = 0; i < m.data.size(); ++i) m.data[i] = static_cast<uint8_t>(i * 7);
  }
  m.size = static_cast<int32_t>(m.data.size());
  return m;
}

own_pose_t pose(int64_t utime, double x) {
  own_pose_t p{};
  p.utime = utime;
  p.frame = own_pose_t::FRAME_ENU;
  p.p_body_in_world[0] = x;
  p.p_body_in_world[2] = 10.0;
  p.q_body_to_world[0] = 1.0;
  p.v_body_in_world[0] = 1.0;
  return p;
}

detections_t detections(int64_t utime, int64_t seq, int n) {
  detections_t d{};
  d.utime = utime;
  d.seq = seq;
  d.image_width = 640;
  d.image_height = 480;
  d.source = detections_t::SOURCE_CNN;
  // Drones (class 0, drone_score = confidence); the second box is a multi-class model's bird (class 2), which the
  // localizer counts and the 1-D follower skips.
  for (int i = 0; i < n; ++i) {
    const bool bird = i == 1;
    d.detections.push_back({320.0f + 40.0f * i, 240.0f, 30.0f, 20.0f, 0.9f, static_cast<int16_t>(bird ? 2 : 0), false,
                            bird ? 0.05f : 0.9f});
  }
  d.num_detections = n;
  return d;
}

targets_t targets(int64_t utime) {
  targets_t t{};
  t.utime = utime;
  t.frame = own_pose_t::FRAME_ENU;
  target_t a{};
  a.track_id = 1;
  a.p_target_in_cam[2] = 10.0;
  a.p_target_in_world[0] = 10.0;
  a.p_target_in_world[2] = 10.0;
  for (int i = 0; i < 9; i += 4) a.position_covariance[i] = a.velocity_covariance[i] = 0.1;
  a.world_valid = true;
  a.range = 10.0;
  a.confidence = 0.9f;
  a.age_s = 1.0f;
  a.source_utime = utime;
  a.predicted_utime = utime;
  t.targets.push_back(a);
  t.num_targets = 1;
  return t;
}

status_t status() {
  status_t s{};
  s.utime = 1700000000000000;
  s.process = "localizer";
  s.pid = 42;
  s.state = status_t::STATE_OK;
  s.detail = "ok";
  s.last_processed_seq = -1;
  channel_stats_t c{};
  c.channel = "DETECTIONS_CAM0";
  c.direction = channel_stats_t::DIRECTION_IN;
  c.count = 10;
  c.rate_hz = 30.0f;
  s.channels.push_back(c);
  s.num_channels = 1;
  return s;
}

ground_truth_t ground_truth() {
  ground_truth_t g{};
  g.utime = 1700000000000000;
  g.image_seq = 3;
  vehicle_truth_t v{};
  v.name = "leader";
  v.vehicle_id = 1;
  v.q_body_to_world[0] = 1.0;
  v.bounding_radius = 0.3;
  g.vehicles.push_back(v);
  g.num_vehicles = 1;
  truth_box_t b{};
  b.vehicle_id = 1;
  b.cx = 100;
  b.cy = 100;
  b.w = 10;
  b.h = 10;
  b.visible = true;
  b.range = 10;
  g.boxes.push_back(b);
  g.num_boxes = 1;
  return g;
}

setpoint_t setpoint() {
  setpoint_t s{};
  s.utime = 1700000000000000;
  s.mode = setpoint_t::MODE_VELOCITY;
  s.velocity[0] = 1.0;
  return s;
}

/// The regression seed of the pre-decode check: a 40-byte image_t whose size field claims 2^31 - 1 bytes.
Bytes huge_image() {
  image_t m = image(image_t::GRAY8, 4, 4);
  m.data.clear();
  m.size = 0;
  Bytes b = encode(m);
  const size_t size_at = b.size() - 4;
  b[size_at] = 0x7f;
  b[size_at + 1] = b[size_at + 2] = b[size_at + 3] = 0xff;
  return b;
}

/// The regression seed of the JPEG size check: a 16 x 8 MJPEG image_t whose JPEG frame header claims 30000 x 30000
/// pixels (cv::imdecode would allocate 2.7 GB for it).
Bytes jpeg_bomb() {
  image_t m = image(image_t::MJPEG, 16, 8);
  for (size_t i = 2; i + 8 < m.data.size(); ++i) {
    if (m.data[i] == 0xFF && m.data[i + 1] == 0xC0) {  // SOF0: FF C0, length, precision, height, width
      m.data[i + 5] = m.data[i + 7] = 30000 >> 8;
      m.data[i + 6] = m.data[i + 8] = 30000 & 0xff;
      break;
    }
  }
  return encode(m);
}

/// MAVLink frames as an autopilot sends them (wingman-mavlink's input), v2 and one v1.
Bytes mavlink_frames() {
  using namespace wingman::mavlink;
  Bytes out;
  auto add = [&](const std::vector<uint8_t>& f) { out.insert(out.end(), f.begin(), f.end()); };
  Heartbeat hb;
  hb.custom_mode = px4_custom_mode(6);
  hb.type = 2;
  hb.autopilot = 12;
  hb.base_mode = 129;
  add(encode(hb, Sender{1, 1, 0}));
  AttitudeQuaternion att;
  att.time_boot_ms = 1000;
  att.q1 = 0.7071f;
  att.q4 = 0.7071f;
  add(encode(att, Sender{1, 1, 1}));
  LocalPositionNed lp;
  lp.time_boot_ms = 1000;
  lp.x = 1.5f;
  lp.z = -3.0f;
  add(encode(lp, Sender{1, 1, 2}));
  Odometry odo;
  odo.time_usec = 1000000;
  odo.pose_covariance[0] = 0.01f;
  odo.frame_id = 1;
  odo.child_frame_id = 12;
  add(encode(odo, Sender{1, 1, 3}));
  Timesync ts;
  ts.tc1 = 5000000000;
  ts.ts1 = 1700000000000000000;
  add(encode(ts, Sender{1, 1, 4}));
  CommandAck ack;
  ack.command = 511;
  add(encode(ack, Sender{1, 1, 5}));
  add(encode(hb, Sender{1, 1, 6}, Version::kV1));
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s CORPUS_DIR\n", argv[0]);
    return 2;
  }
  const fs::path root(argv[1]);
  const int64_t t0 = 1700000000000000;

  const fs::path msgs = root / "lcm_messages";
  save(msgs, "image_gray8", prefixed(0, encode(image(image_t::GRAY8, 8, 4))));
  save(msgs, "image_mjpeg", prefixed(0, encode(image(image_t::MJPEG, 16, 8))));
  save(msgs, "image_huge_size_claim", prefixed(0, huge_image()));
  save(msgs, "detections", prefixed(1, encode(detections(t0, 1, 2))));
  save(msgs, "own_pose", prefixed(2, encode(pose(t0, 0.0))));
  save(msgs, "targets", prefixed(3, encode(targets(t0))));
  save(msgs, "setpoint", prefixed(4, encode(setpoint())));
  save(msgs, "status", prefixed(5, encode(status())));
  save(msgs, "ground_truth", prefixed(6, encode(ground_truth())));

  const fs::path loc = root / "localizer";
  save(loc, "poses_then_detections",
       cat({record(0, encode(pose(t0, 0.0))), record(0, encode(pose(t0 + 33000, 0.1))),
            record(1, encode(detections(t0 + 20000, 1, 1))), record(0, encode(pose(t0 + 66000, 0.2))),
            record(1, encode(detections(t0 + 53000, 2, 2)))}));
  save(loc, "detections_without_pose", cat({record(1, encode(detections(t0, 1, 3)))}));
  save(loc, "scaled_camera", cat({record(2, encode(pose(t0, 0.0))), record(3, encode(detections(t0, 1, 1)))}));

  const fs::path fol = root / "follower";
  save(fol, "formation",
       cat({record(0, encode(pose(t0, 0.0))), record(1, encode(targets(t0 + 1000))),
            record(0, encode(pose(t0 + 20000, 0.1))), record(1, encode(targets(t0 + 30000)))}));
  save(fol, "pid_1d",
       cat({record(0, encode(pose(t0, 0.0))), record(2, encode(detections(t0 + 1000, 1, 1))),
            record(2, encode(detections(t0 + 34000, 2, 1)))}));

  const fs::path det = root / "detector_image";
  save(det, "gray8", encode(image(image_t::GRAY8, 8, 4)));
  save(det, "bgr8", encode(image(image_t::BGR8, 8, 4)));
  save(det, "yuyv", encode(image(image_t::YUYV, 8, 4)));
  save(det, "mjpeg", encode(image(image_t::MJPEG, 16, 8)));
  save(det, "huge_size_claim", huge_image());
  save(det, "mjpeg_header_claims_30000x30000", jpeg_bomb());

  detector::DarknetModel tiny = detector::parse_darknet_cfg_string(fuzz::tiny_cfg(), "tiny.cfg");
  detector::randomize_weights(tiny, 1);
  const std::vector<char> weights = detector::serialize_darknet_weights(tiny);
  const Bytes wbytes(weights.begin(), weights.end());
  const fs::path wdir = root / "darknet_weights";
  save(wdir, "tiny_weights", record(0, wbytes));
  save(wdir, "tiny_cfg_and_weights", cat({record(0, text(fuzz::tiny_cfg())), record(0, wbytes)}));
  save(wdir, "truncated_weights", record(0, Bytes(wbytes.begin(), wbytes.begin() + 40)));

  const fs::path yolo = root / "yolo_dataset";
  save(yolo, "labels",
       cat({record(0, text("0 0.5 0.5 0.1 0.2\n0 0.25 0.75 0.05 0.05\n")), record(1, text("1 0.5 0.5 1 1\n\n"))}));
  save(yolo, "predictions", record(1, text("0 0.5 0.5 0.1 0.2 0.9\n0 0.1 0.1 0.05 0.05 0.3\n")));
  save(yolo, "data_yaml_val",
       cat({record(2 | 4, text("path: .\nval: images/val\ntrain: images/train\nnc: 1\n"
                               "names: [drone]\n")),
            record(0, text("0 0.5 0.5 0.25 0.25\n"))}));
  save(yolo, "data_yaml_train",
       cat({record(2, text("train: [images/train]\nnames: {0: drone}\n")), record(0, text("0 0.4 0.6 0.2 0.3\n"))}));

  const fs::path mav = root / "mavlink_parser";
  const Bytes frames = mavlink_frames();
  save(mav, "autopilot_stream", record(0, frames));
  save(mav, "datagrams",
       cat({record(0, Bytes(frames.begin(), frames.begin() + 40)), record(3, {}),
            record(1, Bytes(frames.begin() + 21, frames.end())), record(3, {})}));
  Bytes damaged = frames;
  damaged[15] ^= 0x10;
  save(mav, "bad_crc_then_frames", record(0, damaged));
  return 0;
}
