// SPDX-License-Identifier: MIT
// wingman-python-bus-peer: the C++ side of the Python udpm tests (tests/python/test_udpm.py), through the LCM C++ API.
//   publish URL LOG ROUNDS PERIOD_MS: each round publishes TARGETS (two targets), IMAGE_CAM0 (a 1280x720 BGR8 image,
//     about 2.7 MB: a fragmented message) and OWN_POSE, and writes the same events to LOG.
//   record URL LOG COUNT TIMEOUT_S: subscribes to every channel, prints "ready", writes what it receives to LOG until
//     COUNT messages or TIMEOUT_S seconds; exit 0 with COUNT messages, 1 without.
#include <lcm/lcm-cpp.hpp>
#include <wingman/image_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/targets_t.hpp>

#include <chrono>
#include <cstdint>
#include <iostream>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

namespace {

int64_t now_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

/// Encodes `msg`, publishes it on `channel` and logs it.
template <class Msg>
void send(lcm::LCM& bus, lcm::LogFile& log, int64_t& eventnum, const std::string& channel, const Msg& msg) {
  std::vector<uint8_t> bytes(static_cast<size_t>(msg.getEncodedSize()));
  if (msg.encode(bytes.data(), 0, static_cast<int>(bytes.size())) < 0) throw std::logic_error("encode " + channel);
  if (bus.publish(channel, bytes.data(), static_cast<unsigned>(bytes.size())) != 0) {
    throw std::runtime_error("publish " + channel);
  }
  lcm::LogEvent ev;
  ev.eventnum = eventnum++;
  ev.timestamp = msg.utime;
  ev.channel = channel;
  ev.datalen = static_cast<int32_t>(bytes.size());
  ev.data = bytes.data();
  if (log.writeEvent(&ev) != 0) throw std::runtime_error("write the log");
}

int publish(const std::string& url, const std::string& log_path, int rounds, int period_ms) {
  lcm::LCM bus(url);
  lcm::LogFile log(log_path, "w");
  if (!bus.good() || !log.good()) throw std::runtime_error("cannot open the bus or the log");
  int64_t eventnum = 0;
  for (int round = 0; round < rounds; ++round) {
    if (round > 0) std::this_thread::sleep_for(std::chrono::milliseconds(period_ms));
    const int64_t utime = now_utime();

    wingman::targets_t targets;
    targets.utime = utime;
    targets.frame = wingman::own_pose_t::FRAME_ENU;
    for (int i = 0; i < 2; ++i) {
      wingman::target_t t{};
      t.track_id = round * 10 + i + 1;
      t.p_target_in_world[0] = 1.5 + i;
      t.p_target_in_world[1] = 12.0 + round;
      t.p_target_in_world[2] = 10.25;
      t.p_target_in_cam[2] = 12.0;
      t.range = 12.0;
      t.world_valid = true;
      t.confidence = 0.75f;
      t.source_utime = utime;
      t.predicted_utime = utime + 20000;
      targets.targets.push_back(t);
    }
    targets.num_targets = static_cast<int32_t>(targets.targets.size());
    send(bus, log, eventnum, "TARGETS", targets);

    wingman::image_t image;
    image.utime = utime;
    image.seq = round;
    image.camera_id = 0;
    image.width = 1280;
    image.height = 720;
    image.stride = 1280 * 3;
    image.pixel_format = wingman::image_t::BGR8;
    image.data.resize(static_cast<size_t>(image.stride) * image.height);
    for (size_t i = 0; i < image.data.size(); ++i)
      image.data[i] = static_cast<uint8_t>((i * 7 + i / 3840 + round) & 0xff);
    image.size = static_cast<int32_t>(image.data.size());
    send(bus, log, eventnum, "IMAGE_CAM0", image);

    wingman::own_pose_t pose{};
    pose.utime = utime;
    pose.frame = wingman::own_pose_t::FRAME_ENU;
    pose.p_body_in_world[2] = 10.0;
    pose.q_body_to_world[0] = 1.0;
    send(bus, log, eventnum, "OWN_POSE", pose);
  }
  return 0;
}

/// Writes every message it receives to a log.
struct Recorder {
  lcm::LogFile* log;
  int64_t count = 0;
  void handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    lcm::LogEvent ev;
    ev.eventnum = count++;
    ev.timestamp = rbuf->recv_utime;
    ev.channel = channel;
    ev.datalen = static_cast<int32_t>(rbuf->data_size);
    ev.data = rbuf->data;
    if (log->writeEvent(&ev) != 0) throw std::runtime_error("write the log");
  }
};

int record(const std::string& url, const std::string& log_path, int count, double timeout_s) {
  lcm::LCM bus(url);
  lcm::LogFile log(log_path, "w");
  if (!bus.good() || !log.good()) throw std::runtime_error("cannot open the bus or the log");
  Recorder recorder{&log};
  bus.subscribe(".*", &Recorder::handle, &recorder);
  std::cout << "ready" << std::endl;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (recorder.count < count && std::chrono::steady_clock::now() < deadline) {
    if (bus.handleTimeout(100) < 0) throw std::runtime_error("handle");
  }
  std::cerr << "wingman-python-bus-peer: recorded " << recorder.count << " messages" << std::endl;
  return recorder.count >= count ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<std::string> args(argv + 1, argv + argc);
  try {
    if (args.size() == 5 && args[0] == "publish")
      return publish(args[1], args[2], std::stoi(args[3]), std::stoi(args[4]));
    if (args.size() == 5 && args[0] == "record")
      return record(args[1], args[2], std::stoi(args[3]), std::stod(args[4]));
  } catch (const std::exception& e) {
    std::cerr << "wingman-python-bus-peer: error: " << e.what() << std::endl;
    return 1;
  }
  std::cerr << "usage: wingman-python-bus-peer publish URL LOG ROUNDS PERIOD_MS | record URL LOG COUNT TIMEOUT_S"
            << std::endl;
  return 2;
}
