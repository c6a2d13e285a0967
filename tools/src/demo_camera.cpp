// SPDX-License-Identifier: MIT
// `wingman demo-camera`: the camera demo's processes through the launcher, their progress read from their heartbeats.
#include "wingman/tools/demo_camera.hpp"

#include "wingman/launcher/bus_watch.hpp"
#include "wingman/launcher/launch_setup.hpp"
#include "wingman/launcher/process_group.hpp"
#include "wingman/tools/log_info.hpp"

#include <fmt/format.h>
#include <wingman/common/config.hpp>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace wingman::tools {

namespace fs = std::filesystem;
using launcher::process;

namespace {

const char* kImageChannel = "IMAGE_CAM0";
const char* kDetectionsChannel = "DETECTIONS_CAM0";

}  // namespace

std::vector<std::string> DemoCameraOptions::validate() const {
  std::vector<std::string> p;
  if (video.empty()) p.push_back(common::problem("demo.video", video, "must name the video to play (VIDEO)"));
  if (!(start_timeout_s > 0.0))
    p.push_back(common::problem("demo.start_timeout_s", start_timeout_s, "must be > 0 seconds (--start-timeout)"));
  if (!(settle_timeout_s > 0.0))
    p.push_back(common::problem("demo.settle_timeout_s", settle_timeout_s, "must be > 0 seconds (--settle-timeout)"));
  return p;
}

int run_demo_camera(const DemoCameraOptions& o, std::ostream& out, std::ostream& err) {
  if (const auto problems = o.validate(); !problems.empty()) throw std::invalid_argument(problems.front());
  if (!std::ifstream(o.video).good()) throw std::invalid_argument(fmt::format("cannot read video '{}'", o.video));
  const std::string bin = launcher::executables_dir(
      o.bin_dir, {"wingman-camera-driver", "wingman-detector", "wingman-localizer", "wingman-follower-ctrl"});
  const std::string url = launcher::private_bus_url(o.lcm_url, "wingman demo-camera", "tools/demo_camera.sh");
  fs::create_directories(o.out);
  const std::string log = (fs::path(o.out) / "demo.lcmlog").string();
  const std::string video = fs::absolute(o.video).string();
  auto exe = [&](const char* name) { return (fs::path(bin) / name).string(); };

  out << "demo: LCM bus " << url << " (private network namespace)" << std::endl;
  launcher::StopSignals signals;
  auto stop_requested = [&] { return signals.requested(); };
  launcher::BusWatch bus(url, fmt::format("{}|{}", kImageChannel, kDetectionsChannel));
  launcher::ProcessGroup group;
  const size_t logger =
      group.start(process("lcm-logger", {"lcm-logger", "--lcm-url=" + url, "--force", "--quiet", log}));
  std::vector<size_t> pipeline;
  for (const char* name : {"wingman-detector", "wingman-localizer", "wingman-follower-ctrl"})
    pipeline.push_back(group.start(process(name, {exe(name), "--lcm-url", url, "--log-level", "warn"})));

  // Ends the demo with `rc` after stopping the pipeline, then the logger (its last heartbeats recorded).
  auto finish = [&](int rc) {
    group.stop(pipeline, launcher::ProcessGroup::kDefaultGraceS);
    bus.spin(300);
    group.stop({logger}, launcher::ProcessGroup::kDefaultGraceS);
    return rc;
  };
  // Whether a pipeline process has ended (named on `err` once).
  bool ended_reported = false;
  auto pipeline_ended = [&] {
    for (const size_t i : pipeline) {
      if (const auto code = group.poll(i)) {
        if (!ended_reported) {
          err << "demo: " << group.spec(i).label() << " ended (exit " << *code
              << "); its command was: " << group.spec(i).command_line() << std::endl;
        }
        ended_reported = true;
        return true;
      }
    }
    return false;
  };
  auto interrupted = [&] {
    if (!signals.requested()) return false;
    err << "demo: stopped by signal " << signals.signal() << std::endl;
    return true;
  };

  // Start-up takes seconds (the detector loads its model and builds its OpenCL kernels): every process publishes a
  // first heartbeat once it listens.
  const std::vector<std::string> missing =
      bus.wait_for_status({"detector", "localizer", "follower_ctrl"}, o.start_timeout_s,
                          [&] { return stop_requested() || pipeline_ended(); });
  if (interrupted()) return finish(130);
  if (!missing.empty()) {
    if (!pipeline_ended())
      err << "demo: no heartbeat within " << o.start_timeout_s << " s from "
          << fmt::format("{}", fmt::join(missing, ", ")) << std::endl;
    return finish(1);
  }

  out << "demo: playing " << o.video << " through wingman-camera-driver" << std::endl;
  // Play the clip once at its own rate, stamped by the wall clock like a live camera.
  const size_t camera = group.start(
      process("wingman-camera-driver", {exe("wingman-camera-driver"), "--set", "source.kind=file", "--set",
                                        fmt::format("file={{path: \"{}\", mode: realtime, loop: false}}", video),
                                        "--lcm-url", url, "--status-period", "0.5"}));
  for (;;) {  // the bus is read while the clip plays, so nothing queues up
    bus.spin(50);
    if (interrupted()) return finish(130);
    if (group.poll(camera)) break;
    if (pipeline_ended()) return finish(1);
  }
  if (const int code = *group.poll(camera); code != 0) {
    err << "demo: wingman-camera-driver failed (exit " << code << ")" << std::endl;
    return finish(1);
  }
  // The detector may still be working on the last frames (or building a network for the clip's frame size): wait
  // until its heartbeat accounts for every frame on the bus (detected or counted as dropped), then one more heartbeat
  // from every process.
  const auto settled = [&] {
    const int64_t images = bus.count(kImageChannel);
    const status_t* det = bus.status("detector");
    return images > 0 && det != nullptr && det->messages_handled >= images &&
           bus.count(kDetectionsChannel) + det->drops_total >= images;
  };
  if (!bus.spin_until(settled, o.settle_timeout_s, [&] { return stop_requested() || pipeline_ended(); })) {
    if (interrupted()) return finish(130);
    if (!pipeline_ended()) {
      const status_t* det = bus.status("detector");
      err << "demo: the detector did not account for every frame within " << o.settle_timeout_s
          << " s: " << bus.count(kImageChannel) << " images, " << bus.count(kDetectionsChannel)
          << " detections, handled " << (det ? det->messages_handled : 0) << ", drops " << (det ? det->drops_total : 0)
          << std::endl;
    }
    return finish(1);
  }
  bus.spin(1200);
  finish(0);

  out << "\ndemo: what arrived on the bus (recorded by lcm-logger in " << log << "):" << std::endl;
  const std::string snapshot = (fs::path(o.out) / "last_frame.png").string();
  const LogSummary summary = summarize_log(log, snapshot, false, &err);
  out << summary.report() << std::flush;
  if (summary.images_with_pixels > 0) out << "last image saved to " << snapshot << std::endl;
  return 0;
}

}  // namespace wingman::tools
