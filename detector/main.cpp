// SPDX-License-Identifier: MIT
// wingman-detector: camera images in, drone detections out (Algorithm 2 on an OpenCL or CPU backend).
#include "wingman/detector/detection_message.hpp"
#include "wingman/detector/detector_options.hpp"
#include "wingman/detector/model_loader.hpp"
#include "wingman/detector/preprocess.hpp"
#include "wingman/detector/sized_detector.hpp"
#include "wingman/detector/track_windows.hpp"

#include <wingman/common/latest_worker.hpp>
#include <wingman/common/runtime.hpp>
#include <wingman/common/sequence_gaps.hpp>
#include <wingman/common/time_sanity.hpp>

#include <fmt/format.h>

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <vector>

namespace {

using namespace wingman;

/// The detector's clock: image times only (time.*). admit() throws std::invalid_argument naming the field, its value
/// and the rule for an image dated too far ahead or out of order (the runtime drops and counts it); a resync is
/// logged once.
class ImageClock {
 public:
  explicit ImageClock(const common::TimeSanityOptions& options)
      : clock_(options), input_(clock_.add_input("image_t.utime", "image", true)) {}
  void admit(const image_t& img) {
    const common::TimeAdmission a = clock_.admit(input_, img.utime);
    if (!a.accepted()) throw std::invalid_argument(a.problem);
    if (a.resynced()) spdlog::warn("{}", a.problem);
  }

 private:
  common::StageClock clock_;
  int input_;
};

/// Without weights: check and count images only (the state says why).
int run_without_model(common::Runtime& rt, const detector::DetectorOptions& o, const common::ImageLimits& limits) {
  rt.status().set_state(status_t::STATE_DEGRADED, "no model.weights configured: images are checked and counted only");
  ImageClock clock(o.time);
  rt.subscribe<image_t>(
      o.input_channel,
      [&rt, &clock](const image_t& img) {
        clock.admit(img);
        rt.status().set_last_processed_seq(img.seq);
      },
      [limits](const image_t& img) { return common::validate_message(img, limits); });
  return rt.spin();
}

int run(common::Runtime& rt, const detector::DetectorOptions& o) {
  const common::ImageLimits limits{o.max_image_width, o.max_image_height};
  // Oversized images are dropped before they are decoded (no allocation for their pixels).
  common::MessageLimits message_limits;
  message_limits.image = limits;
  message_limits.max_message_bytes =
      std::max<std::size_t>(message_limits.max_message_bytes, message_limits.image_bytes_limit() + 4096);
  rt.set_message_limits(message_limits);
  rt.status().declare_output(o.output_channel);
  if (o.weights.empty()) return run_without_model(rt, o, limits);

  detector::DarknetModel model = detector::load_model(o.cfg, o.weights);
  const std::string model_id = detector::weights_model_id(o.weights);                // detections_t.model_id
  const detector::InputSize input_size = *detector::InputSize::parse(o.input_size);  // validated with the options
  // model.backend = opencl: no usable OpenCL device, or a kernel that fails to build, throws here (exit 1, one line).
  // The first network is built at start-up (the cfg's size, or model.input_size's WxH); with input_size auto,
  // frames of another aspect build another one when the first of them arrives.
  bool built_once = false;  // a fallback warns at start-up only; a later network for another frame size says it as info
  // What a network build says: logged, and (with `state`) the heartbeat's detail. In real-time mode builds run on
  // the worker thread, which queues these for the thread that owns the runtime and the log.
  struct Note {
    spdlog::level::level_enum level = spdlog::level::info;
    std::string text;
    std::string state;  ///< non-empty: the new STATE_OK detail
  };
  bool queue_notes = false;  // set before the worker thread starts; then notes go to `queued_notes`
  std::mutex notes_mutex;
  std::vector<Note> queued_notes;
  auto say = [&](Note note) {
    if (queue_notes) {
      std::lock_guard<std::mutex> lock(notes_mutex);
      queued_notes.push_back(std::move(note));
      return;
    }
    spdlog::log(note.level, note.text);
    if (!note.state.empty()) rt.status().set_state(status_t::STATE_OK, note.state);
  };
  std::string auto_kind;  // what model.backend auto chose at start-up ("opencl" or "cpu"), for later builds
  std::string auto_why;   // why it chose so (said again for a later network)
  auto make_backend = [&](const detector::DarknetModel& sized) {
    std::string why;
    const auto t_backend = std::chrono::steady_clock::now();
    // model.backend auto chooses (it measures both) at start-up; a network for another
    // frame size later takes the same kind without measuring again (seconds in which no frame would be detected).
    const bool reuse = o.backend == "auto" && !auto_kind.empty();
    auto backend = detector::make_backend(reuse ? auto_kind : o.backend, sized, o.opencl, o.opencl.max_batch, &why);
    if (reuse) {
      why = fmt::format("{}; kept for the {}x{} network", auto_why, sized.net.width, sized.net.height);
    } else if (o.backend == "auto") {
      auto_kind = backend->name().rfind("opencl", 0) == 0 ? "opencl" : "cpu";
      auto_why = why;
    }
    const double backend_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_backend).count();
    const std::string net = fmt::format("network input {}x{}", sized.net.width, sized.net.height);
    // The heartbeat says which backend runs, and why, for as long as nothing else needs saying.
    if (why.find("no usable OpenCL device") != std::string::npos && !built_once) {
      // auto fell back: warned once
      say({spdlog::level::warn, fmt::format("{}; running on the CPU (chosen in {:.2f} s; {})", why, backend_s, net),
           why});
    } else {
      say({spdlog::level::info, fmt::format("{} (chosen in {:.2f} s; {})", why, backend_s, net), why});
    }
    built_once = true;
    return backend;
  };
  auto on_build = [&](cv::Size net, cv::Size image) {
    if (image.empty()) return;  // the start-up build: make_backend said it
    say({spdlog::level::info,
         fmt::format("model.input_size {}: network input {}x{} for {}x{} images", input_size.to_string(), net.width,
                     net.height, image.width, image.height),
         ""});
  };
  // Tracker-driven windows: the localizer's predictions, and a second network at the crop size, built after the single
  // pass's (with model.backend auto, the single pass's network decides the backend and the window's takes the same).
  std::optional<detector::DarknetModel> window_model;
  if (o.windows.enabled) window_model = model;
  std::mutex windows_mutex;  // the newest windows: written by the LCM thread, read where frames are detected
  std::shared_ptr<const track_windows_t> newest_windows;  // swapped whole: a frame takes the pointer, not a copy
  int32_t image_camera_id = -1;  // the camera of the frames seen (a windows message for another is a counted drop)
  detector::WindowStats window_stats;
  detector::SizedDetector pipeline(o.detection, std::move(model), input_size, make_backend, on_build);
  std::unique_ptr<detector::WindowDetector> window_detector;
  if (window_model)
    window_detector = std::make_unique<detector::WindowDetector>(o.windows, o.detection, *window_model, make_backend);
  window_model.reset();

  // Publishes the detections of frame `img` (its header is enough) and marks it processed.
  auto publish_detections = [&](const image_t& img, const std::vector<detector::Box>& boxes, int64_t latency_us) {
    detections_t out{};
    out.utime = img.utime;
    out.seq = img.seq;
    out.camera_id = img.camera_id;
    out.image_width = img.width;
    out.image_height = img.height;
    out.source = detections_t::SOURCE_CNN;
    out.inference_latency_us = static_cast<int32_t>(latency_us);
    out.model_id = model_id;
    // Every box, drone or distractor (class_id != 0 with a multi-class model): the consumers choose.
    for (const auto& b : boxes) out.detections.push_back(detector::to_detection(b));
    out.num_detections = static_cast<int32_t>(out.detections.size());
    rt.publish(o.output_channel, out);
    rt.status().set_last_processed_seq(img.seq);
  };
  // Runs the detector on one frame; a frame whose pixels cannot be read throws std::invalid_argument (a counted drop).
  struct Detected {
    std::vector<detector::Box> boxes;
    int64_t latency_us = 0;  ///< the time detect() took (the one wall-clock field of detections_t)
  };
  auto detect = [&](const image_t& img) {
    std::string error;
    const cv::Mat bgr = detector::image_to_bgr(img, &error);
    if (!error.empty()) throw std::invalid_argument(error);
    const auto t0 = std::chrono::steady_clock::now();
    Detected d;
    d.boxes = pipeline.detect(bgr);
    if (window_detector) {
      std::shared_ptr<const track_windows_t> windows;
      {
        std::lock_guard<std::mutex> lock(windows_mutex);
        windows = newest_windows;
      }
      if (windows) {
        const cv::Size size(bgr.cols, bgr.rows);
        const std::vector<detector::Window> search = detector::windows_to_search(
            *windows, img.utime, size, img.camera_id, pipeline.net_px_per_image_px(size), o.windows);
        if (!search.empty()) d.boxes = window_detector->detect(bgr, std::move(d.boxes), search, &window_stats);
      }
    }
    d.latency_us = std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::steady_clock::now() - t0).count();
    return d;
  };
  auto validate = [limits](const image_t& img) { return common::validate_message(img, limits); };
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
  ImageClock clock(o.time);
  if (window_detector) {
    rt.subscribe<track_windows_t>(o.windows.channel, [&](const track_windows_t& w) {
      if (image_camera_id >= 0 && w.camera_id != image_camera_id)
        throw std::invalid_argument(
            fmt::format("track_windows_t.camera_id = {}: the frames are camera {}", w.camera_id, image_camera_id));
      auto fresh = std::make_shared<const track_windows_t>(w);
      std::lock_guard<std::mutex> lock(windows_mutex);
      newest_windows = std::move(fresh);
    });
  }
  auto log_windows = [&] {
    if (window_detector)
      spdlog::info("windows: {} searched in {} crops, {} found their track's drone", window_stats.windows,
                   window_stats.crops, window_stats.found);
  };
  auto note_camera = [&](const image_t& img) { image_camera_id = img.camera_id; };

  if (o.mode == "replay" || rt.input_is_file()) {
    // Every frame, in order, inside its handler: deterministic, and lockstep-friendly.
    rt.subscribe<image_t>(
        o.input_channel,
        [&](const image_t& img) {
          count_gap(img);
          accounted();
          note_camera(img);
          try {
            clock.admit(img);  // a frame dated ahead or out of order is a counted drop: never detected
            const Detected d = detect(img);
            publish_detections(img, d.boxes, d.latency_us);
          } catch (...) {
            handler_threw = true;  // the runtime drops and counts it
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
    Detected result;
    std::string error;  ///< non-empty: the frame was dropped for this reason
  };
  // Builds for a new frame size run on the worker: what they say is queued for this thread.
  queue_notes = true;
  rt.set_record_handler_latency(false);  // the handler only queues; the detection's time is the latency
  // An exception other than a bad frame's (e.g. an OpenCL error) ends the worker; collect() rethrows it here.
  common::LatestWorker<image_t, Done> worker(
      [&](image_t& img) {
        Done d;
        try {
          d.result = detect(img);
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
        note_camera(img);
        try {
          clock.admit(img);  // a frame dated ahead or out of order is a counted drop: never detected
        } catch (...) {
          handler_threw = true;  // the runtime drops and counts it
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
    std::vector<Note> notes;
    {
      std::lock_guard<std::mutex> lock(notes_mutex);
      notes.swap(queued_notes);
    }
    for (const Note& note : notes) {
      spdlog::log(note.level, note.text);
      if (!note.state.empty()) rt.status().set_state(status_t::STATE_OK, note.state);
    }
    for (const Done& d : taken.results) {
      if (!d.error.empty()) {
        rt.status().item_dropped(o.input_channel, std::string("channel ") + o.input_channel + ": " + d.error);
        // This drop is not a message the runtime rejected: keep it out of the next gap (the counts saturate).
        if (drops_accounted < std::numeric_limits<int64_t>::max()) ++drops_accounted;
        continue;
      }
      publish_detections(d.meta, d.result.boxes, d.result.latency_us);
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
