// SPDX-License-Identifier: MIT
// wingman-detector: camera images in, drone detections out (Algorithm 2 on an OpenCL or CPU backend).
// The frame loop is detector::Detector; this file is the process around it: options, runtime, subscriptions, the
// real-time worker, drop counting and publishing.
#include "wingman/detector/detector.hpp"
#include "wingman/detector/detector_options.hpp"

#include <wingman/common/latest_worker.hpp>
#include <wingman/common/runtime.hpp>
#include <wingman/common/sequence_gaps.hpp>

#include <fmt/format.h>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace wingman;

int run(common::Runtime& rt, const detector::DetectorOptions& o) {
  const common::ImageLimits limits{o.max_image_width, o.max_image_height};
  // Oversized images are dropped before they are decoded (no allocation for their pixels).
  common::MessageLimits message_limits;
  message_limits.image = limits;
  message_limits.max_message_bytes =
      std::max<std::size_t>(message_limits.max_message_bytes, message_limits.image_bytes_limit() + 4096);
  rt.set_message_limits(message_limits);
  rt.status().declare_output(o.output_channel);
  // Loads the model and builds the networks: model.backend = opencl without a usable OpenCL device, or a kernel that
  // fails to build, throws here (exit 1, one line).
  detector::Detector det(o);
  // What the detector says (network builds, a time resync): logged, and (with a state) the heartbeat's detail. Only
  // this thread touches the runtime and the log.
  auto say_notes = [&] {
    for (const detector::DetectorNote& note : det.take_notes()) {
      spdlog::log(note.level == detector::DetectorNote::Level::kWarn ? spdlog::level::warn : spdlog::level::info,
                  note.text);
      if (!note.state.empty()) rt.status().set_state(status_t::STATE_OK, note.state);
    }
  };
  say_notes();
  auto validate = [limits](const image_t& img) { return common::validate_message(img, limits); };
  if (!det.has_model()) {
    // Without weights: check and count images only (the state says why).
    rt.status().set_state(status_t::STATE_DEGRADED, det.degraded());
    rt.subscribe<image_t>(
        o.input_channel,
        [&](const image_t& img) {
          det.on_image(img);
          say_notes();
          rt.status().set_last_processed_seq(img.seq);
        },
        validate);
    return rt.spin();
  }

  // Publishes the detections of a frame and marks it processed.
  auto publish = [&](const detections_t& out) {
    rt.publish(o.output_channel, out);
    rt.status().set_last_processed_seq(out.seq);
  };
  // Frames that never reached this process (lost at the camera, or on the bus when a receive buffer overflows)
  // show only as gaps in image_t.seq: each missing frame is counted as a drop on the input channel. Messages the
  // runtime dropped in between (undecodable or invalid) did arrive and are counted already, so they are taken off
  // the gap.
  common::SequenceGapCounter gaps;
  int64_t drops_accounted = 0;  // the channel's drops when this code last accounted for them
  bool handler_threw = false;   // the previous frame's handler threw: the runtime counted that drop after it
  auto count_gap = [&](const image_t& img) {
    const int64_t rejected = rt.status().input_drops(o.input_channel) - drops_accounted - (handler_threw ? 1 : 0);
    handler_threw = false;
    const int64_t missing = std::max<int64_t>(0, gaps.observe(img.seq) - rejected);
    // One step whatever the gap (a hostile seq jump of 2^62 once hung this loop, issue 33).
    if (missing > 0) {
      rt.status().items_dropped(o.input_channel, missing,
                                fmt::format("channel {}: {} frame(s) missing before seq {} (lost "
                                            "upstream: at the camera or on the bus)",
                                            o.input_channel, missing, img.seq));
    }
  };
  auto accounted = [&] { drops_accounted = rt.status().input_drops(o.input_channel); };
  // Tracker-driven windows: another camera's are a counted drop (thrown naming the field).
  if (det.windows_enabled())
    rt.subscribe<track_windows_t>(o.windows.channel, [&](const track_windows_t& w) { det.on_windows(w); });
  auto log_windows = [&] {
    const detector::WindowStats& s = det.window_stats();
    if (det.windows_enabled())
      spdlog::info("windows: {} searched in {} crops, {} found their track's drone", s.windows, s.crops, s.found);
    if (const detector::MotionStats* m = det.motion_stats()) {
      const detector::WindowStats& w = det.motion_window_stats();
      spdlog::info(
          "motion: {} of {} frames compared ({} not aligned, {} restarts), {} moving blobs, {} searched in {} crops, "
          "{} found a drone",
          m->compared, m->frames, m->unaligned, m->restarts, m->blobs, w.windows, w.crops, w.found);
    }
  };

  if (o.mode == "replay" || rt.input_is_file()) {
    // Every frame, in order, inside its handler: deterministic, and lockstep-friendly.
    rt.subscribe<image_t>(
        o.input_channel,
        [&](const image_t& img) {
          count_gap(img);
          accounted();
          try {
            const auto out = det.on_image(img);  // a frame dated ahead or out of order is a counted drop
            say_notes();
            publish(*out);
          } catch (...) {
            handler_threw = true;  // the runtime drops and counts it
            say_notes();
            throw;
          }
        },
        validate);
    const int rc = rt.spin();
    log_windows();
    return rc;
  }
  // Real time: a worker thread detects while this thread keeps reading the bus, so no frame waits in a socket
  // buffer while a detection (or the build of a network for a new frame size) runs: every frame is received,
  // and a frame superseded by a newer one before the worker took it is a counted drop. Only this thread touches
  // the runtime and the log; the worker hands back what it did and wakes it.
  struct Done {
    image_t meta;  ///< the frame's header (no pixels)
    detector::FrameDetections result;
    std::string error;  ///< non-empty: the frame was dropped for this reason
  };
  rt.set_record_handler_latency(false);  // the handler only queues; the detection's time is the latency
  // An exception other than a bad frame's (e.g. an OpenCL error) ends the worker; collect() rethrows it here.
  common::LatestWorker<image_t, Done> worker(
      [&](image_t& img) {
        Done d;
        try {
          d.result = det.detect(img);
        } catch (const std::invalid_argument& e) {
          d.error = e.what();
        }
        std::vector<uint8_t>().swap(img.data);  // the header is all the publisher needs
        d.meta = std::move(img);
        return d;
      },
      [&rt] { rt.wake(); });
  rt.subscribe<image_t>(
      o.input_channel,
      [&](const image_t& img) {
        count_gap(img);
        accounted();
        try {
          det.admit(img);  // a frame dated ahead or out of order is a counted drop: never detected
          say_notes();
        } catch (...) {
          handler_threw = true;  // the runtime drops and counts it
          say_notes();
          throw;
        }
        if (const auto superseded = worker.offer(img)) {  // the copy is made here, outside the worker's lock
          rt.status().item_dropped(
              o.input_channel, fmt::format("channel {}: frame seq {} superseded by seq {} while busy", o.input_channel,
                                           superseded->seq, img.seq));
        }
        accounted();
      },
      validate);
  // Publishes what the worker finished, in order; rethrows its failure.
  auto collect = [&] {
    // Results first, then the notes: a build's notes are queued before the frame's result, so each result is
    // published after what its build said.
    auto taken = worker.take();
    say_notes();
    for (const Done& d : taken.results) {
      if (!d.error.empty()) {
        rt.status().item_dropped(o.input_channel, std::string("channel ") + o.input_channel + ": " + d.error);
        // This drop is not a message the runtime rejected: keep it out of the next gap (the counts saturate).
        if (drops_accounted < std::numeric_limits<int64_t>::max()) ++drops_accounted;
        continue;
      }
      publish(det.message(d.meta, d.result));
      rt.status().record_latency_ms(static_cast<double>(d.result.latency_us) / 1000.0);
    }
    if (taken.failure) std::rethrow_exception(taken.failure);
  };
  while (rt.spin_once(100)) collect();  // on an exception the worker's destructor stops it
  // Stopping: a frame still waiting is dropped and counted; the one being detected is finished and published.
  if (const auto waiting = worker.stop()) {
    rt.status().item_dropped(o.input_channel, fmt::format("channel {}: frame seq {} not processed: stopping",
                                                          o.input_channel, waiting->seq));
  }
  collect();
  log_windows();
  return rt.shutdown();
}

}  // namespace

int main(int argc, char** argv) {
  const common::ProcessInfo info{"detector", "wingman-detector", "Detects drones in camera images (OpenCL CNN)"};
  return common::run_process<detector::DetectorOptions>(info, argc, argv, run);
}
