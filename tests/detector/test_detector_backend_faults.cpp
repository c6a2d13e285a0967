// SPDX-License-Identifier: MIT
// wingman-detector as a process without a usable OpenCL device: no platform at all (OCL_ICD_VENDORS pointing at an
// empty folder), a platform without devices (PoCL asked for a device kind it lacks), and a device whose kernels fail
// to build (an option its compiler rejects). model.backend = opencl: exit 1 with one line; auto: the CPU backend, one
// warning, and the heartbeat names the backend (in replay mode, where auto does not time the backends, and in
// realtime mode, where it does).
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <wingman/detections_t.hpp>
#include <wingman/image_t.hpp>
#include <wingman/status_t.hpp>

#include <fstream>
#include <sstream>

namespace {

using namespace std::chrono_literals;
using wingman::testing::bin_path;
using wingman::testing::LogEvent;
using wingman::testing::make_event;
using wingman::testing::read_log;
using wingman::testing::run;
using wingman::testing::RunResult;
using wingman::testing::TempDir;

constexpr int kFrames = 3;

std::string write_frames(const TempDir& dir) {
  std::vector<LogEvent> events;
  for (int i = 0; i < kFrames; ++i) {
    wingman::image_t img{};
    img.utime = 1700000000000000 + i * 33333;
    img.seq = i;
    img.width = 320;
    img.height = 240;
    img.stride = 320 * 3;
    img.pixel_format = wingman::image_t::BGR8;
    img.data.assign(static_cast<size_t>(img.stride * img.height), static_cast<uint8_t>(40 * i));
    img.size = static_cast<int32_t>(img.data.size());
    events.push_back(make_event("IMAGE_CAM0", img, img.utime));
  }
  const std::string path = dir.file("frames.lcmlog");
  wingman::testing::write_log(path, events);
  return path;
}

std::string write_config(const TempDir& dir, const std::string& backend, const std::string& build_options = "",
                         const std::string& mode = "replay") {
  const std::string path = dir.file("detector-" + backend + "-" + mode + ".yaml");
  std::ofstream f(path);
  f << "input: {mode: " << mode << "}\nmodel: {backend: " << backend << "}\n";
  if (!build_options.empty()) f << "opencl: {build_options: \"" << build_options << "\"}\n";
  return path;
}

/// Runs the detector on the frames with `env` (VAR=value entries) set; a heartbeat follows every frame (--lockstep).
RunResult run_detector(const TempDir& dir, const std::string& config, const std::vector<std::string>& env,
                       const std::string& out) {
  std::vector<std::string> argv = {"env"};
  argv.insert(argv.end(), env.begin(), env.end());
  for (const std::string& a : {bin_path("wingman-detector"), std::string("--config"), config, std::string("--lcm-in"),
                               "file://" + write_frames(dir) + "?speed=0", std::string("--lcm-out"),
                               "file://" + out + "?mode=w", std::string("--lockstep")}) {
    argv.push_back(a);
  }
  return run(argv, 120s);
}

std::vector<std::string> lines(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) {
    if (!l.empty()) out.push_back(l);
  }
  return out;
}

/// The run failed at start-up with exactly one line on stderr: the fatal error.
void expect_one_line_error(const RunResult& r, const std::vector<std::string>& must_contain) {
  EXPECT_EQ(r.exit_code, 1) << r.err;
  std::vector<std::string> errors;
  for (const auto& l : lines(r.err)) {
    if (l.find(" info: ") == std::string::npos) errors.push_back(l);  // the "started" info line is not an error
  }
  ASSERT_EQ(errors.size(), 1u) << r.err;
  EXPECT_EQ(errors[0].rfind("wingman-detector: error: ", 0), 0u) << errors[0];
  for (const auto& s : must_contain)
    EXPECT_NE(errors[0].find(s), std::string::npos) << "'" << s << "' in " << errors[0];
}

/// The run processed every frame (replay mode; realtime mode: at least one, the newest) on the CPU backend, warned once
/// why, and its heartbeat said so.
void expect_cpu_fallback(const RunResult& r, const std::string& out, const std::string& reason, bool replay = true) {
  const std::string said =
      replay ? "backend cpu (auto, not timed: no usable OpenCL device" : "backend cpu (auto: no usable OpenCL device";
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int warnings = 0;
  for (const auto& l : lines(r.err)) {
    if (l.find(" warning: ") == std::string::npos) continue;
    ++warnings;
    EXPECT_NE(l.find(said), std::string::npos) << l;
    EXPECT_NE(l.find(reason), std::string::npos) << "'" << reason << "' in " << l;
  }
  EXPECT_EQ(warnings, 1) << r.err;
  // The frames are 4:3: model.input_size auto built a second network for them (the cfg's is 640x352), without a
  // second warning.
  EXPECT_NE(r.err.find("model.input_size auto: network input 640x480 for 320x240 images"), std::string::npos) << r.err;
  int detections = 0;
  bool detail_names_backend = false;
  for (const auto& e : read_log(out)) {
    if (e.channel == "DETECTIONS_CAM0") ++detections;
    if (e.channel != "STATUS_DETECTOR") continue;
    wingman::status_t s;
    ASSERT_GE(s.decode(e.data.data(), 0, static_cast<int>(e.data.size())), 0);
    if (s.state == wingman::status_t::STATE_OK && s.detail.rfind(said, 0) == 0) detail_names_backend = true;
  }
  if (replay) {
    EXPECT_EQ(detections, kFrames);
  } else {
    EXPECT_GE(detections, 1);
    EXPECT_LE(detections, kFrames);
  }
  EXPECT_TRUE(detail_names_backend) << "no STATUS_DETECTOR heartbeat with state OK naming the CPU backend";
}

const char* kNoPlatform = "no OpenCL platform found";

TEST(DetectorBackendFaults, OpenClWithoutAnyPlatformExitsOneWithOneLine) {
  TempDir dir;
  const auto r =
      run_detector(dir, write_config(dir, "opencl"), {"OCL_ICD_VENDORS=" + dir.path()}, dir.file("o.lcmlog"));
  expect_one_line_error(r, {kNoPlatform});
}

TEST(DetectorBackendFaults, AutoWithoutAnyPlatformRunsOnTheCpuWithOneWarning) {
  TempDir dir;
  const std::string out = dir.file("out.lcmlog");
  const auto r = run_detector(dir, write_config(dir, "auto"), {"OCL_ICD_VENDORS=" + dir.path()}, out);
  expect_cpu_fallback(r, out, kNoPlatform);
}

TEST(DetectorBackendFaults, AutoInRealtimeModeWithoutAnyPlatformRunsOnTheCpuWithOneWarning) {
  TempDir dir;
  const std::string out = dir.file("out.lcmlog");
  const auto r = run_detector(dir, write_config(dir, "auto", "", "realtime"), {"OCL_ICD_VENDORS=" + dir.path()}, out);
  expect_cpu_fallback(r, out, kNoPlatform, /*replay=*/false);
}

TEST(DetectorBackendFaults, OpenClPlatformWithoutDevicesExitsOneWithOneLine) {
  // PoCL built without CUDA lists its platform with no device when asked only for CUDA devices.
  TempDir dir;
  const auto r = run_detector(dir, write_config(dir, "opencl"), {"POCL_DEVICES=cuda"}, dir.file("o.lcmlog"));
  expect_one_line_error(r, {"matches no device of platform", "(no devices)"});
}

TEST(DetectorBackendFaults, OpenClKernelBuildFailureExitsOneWithOneLine) {
  TempDir dir;
  const auto r = run_detector(dir, write_config(dir, "opencl", "-wingman-no-such-option"), {}, dir.file("o.lcmlog"));
  expect_one_line_error(r, {"building OpenCL program", "-wingman-no-such-option"});
}

TEST(DetectorBackendFaults, AutoWithKernelBuildFailureRunsOnTheCpuWithOneWarning) {
  TempDir dir;
  const std::string out = dir.file("out.lcmlog");
  const auto r = run_detector(dir, write_config(dir, "auto", "-wingman-no-such-option"), {}, out);
  expect_cpu_fallback(r, out, "building OpenCL program");
}

}  // namespace
