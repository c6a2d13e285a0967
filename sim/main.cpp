// SPDX-License-Identifier: MIT
// wingman-sim: flies a scenario and publishes what the camera vehicle's camera and autopilot would (images, own pose)
// plus ground truth; takes the follower's setpoints; advances simulated time by messages (lockstep), freely or in
// real time.
#include "wingman/sim/mavlink_vehicle.hpp"
#include "wingman/sim/renderer.hpp"
#include "wingman/sim/scenario.hpp"
#include "wingman/sim/sim_cameras.hpp"
#include "wingman/sim/sim_options.hpp"
#include "wingman/sim/simulator.hpp"
#include "wingman/sim/truth_detections.hpp"

#include <wingman/common/progress.hpp>
#include <wingman/common/runtime.hpp>
#include <wingman/geometry/calibration.hpp>
#include <wingman/launcher/bus_watch.hpp>
#include <wingman/mavlink/parser.hpp>
#include <wingman/mavlink_bridge/link.hpp>
#include <wingman/mavlink_bridge/link_reader.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>

namespace {

using namespace wingman;
using Clock = std::chrono::steady_clock;
namespace common = wingman::common;

int remaining_ms(Clock::time_point deadline, int cap_ms) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return static_cast<int>(std::clamp<int64_t>(left, 0, cap_ms));
}

/// Waits until every process instance of `names` (status_t.process, on its STATUS_<NAME> channel) has published a
/// heartbeat on the input bus, bounded by timeout_s of wall clock: the launchers' launcher::BusWatch, the runtime
/// spinning between its spins (our heartbeat, signals, inputs). Throws naming those not seen.
void wait_for_processes(common::Runtime& rt, const std::vector<std::string>& names, double timeout_s) {
  if (names.empty()) return;
  if (rt.input_is_file())
    throw std::runtime_error("sync.wait_for: heartbeats are heard on a bus, not read from a file:// input");
  const common::RuntimeOptions& ro = rt.options();
  launcher::BusWatch watch(ro.lcm_in.empty() ? ro.lcm_url : ro.lcm_in);
  spdlog::info("waiting up to {} s for the status of: {}", timeout_s, fmt::join(names, ", "));
  const std::vector<std::string> missing = watch.wait_for_status(names, timeout_s, [&] { return !rt.spin_once(0); });
  if (rt.stop_requested()) return;
  if (!missing.empty()) {
    std::vector<std::string> m;
    for (const auto& name : missing) m.push_back(name + " (" + common::status_channel(name) + ")");
    throw std::runtime_error(
        fmt::format("sync.wait_for: no status heartbeat within {} s from {}", timeout_s, fmt::join(m, ", ")));
  }
}

/// The status channel entry of the MAVLink link (autopilot: mavlink).
const std::string kLinkChannel = "MAVLINK";

/// The camera vehicle's autopilot as a MAVLink vehicle (autopilot: mavlink): the link, its parser and the vehicle's
/// rules. service() handles what has arrived, at the simulator's present time, and gives the resulting commands to the
/// simulator; the link's own reads wake the runtime.
class MavlinkSide {
 public:
  MavlinkSide(common::Runtime& rt, const sim::MavlinkVehicleOptions& o, sim::Simulator& simulator)
      : rt_(rt),
        o_(o),
        simulator_(simulator),
        vehicle_(o, simulator.scenario().start_utime),
        link_(mavlink_bridge::make_link(o.url, 0), 1.0, 4096, [&rt] { rt.wake(); }) {
    rt.status().declare_input(kLinkChannel);
  }

  sim::MavlinkVehicle& vehicle() { return vehicle_; }

  /// Handles the link's waiting reads and sends what is due (our HEARTBEAT on the wall clock).
  void service() {
    chunks_.clear();
    link_.take(chunks_);
    for (const auto& c : chunks_) {
      auto on_frame = [&](const mavlink::Frame& f) {
        rt_.status().input(kLinkChannel, 0);
        vehicle_.on_frame(f, simulator_.now_utime(), out_);
      };
      if (!c.event.empty()) {
        if (c.lost) parser_.end_of_datagram(on_frame);
        if (c.event.rfind("link open", 0) == 0) {
          spdlog::info("{}", c.event);
        } else {
          rt_.status().input_dropped(kLinkChannel, c.event);
          spdlog::warn("{}", c.event);
        }
        continue;
      }
      parser_.feed(c.bytes.data(), c.bytes.size(), on_frame);
      if (c.datagram) parser_.end_of_datagram(on_frame);
    }
    for (const int64_t n = parser_.stats().bad_crc + parser_.stats().truncated + parser_.stats().bad_length +
                           parser_.stats().signed_refused + parser_.stats().incompatible_flags;
         parser_drops_ < n; ++parser_drops_)
      rt_.status().input_dropped(kLinkChannel, "MAVLink: a bad frame (checksum, length, signed or unknown flags)");
    const auto now = Clock::now();
    if (!last_heartbeat_ || now - *last_heartbeat_ >= std::chrono::duration<double>(o_.heartbeat_period_s)) {
      vehicle_.heartbeat(out_);
      last_heartbeat_ = now;
    }
    flush();
  }

  /// The frame's time: timeouts, the pilot, telemetry of the camera vehicle (its reported pose, with the pose
  /// error and the covariance of SimFrame::own_pose).
  void on_frame_time(const sim::SimFrame& frame) {
    sim::ReportedPoseUncertainty u;
    if (frame.own_pose.has_covariance) {
      u.known = true;
      u.position_var_m2 = frame.own_pose.cov_p_body_in_world[0];
      u.attitude_var_rad2 = frame.own_pose.var_rpy_body[0];
    }
    vehicle_.on_frame_time(simulator_.now_utime(), frame.own_reported, out_, u);
    flush();
  }

  /// Sends a TIMESYNC request: its answer (pong()) comes after the companion handled everything before it.
  int64_t ping() {
    const int64_t ts1 = vehicle_.ping(simulator_.now_utime(), out_);
    flush();
    return ts1;
  }
  std::optional<int64_t> pong() const { return pong_; }
  int64_t write_failures() const { return write_failures_; }
  int64_t command_errors() const { return command_errors_; }

 private:
  void flush() {
    for (const auto& f : out_.frames)
      if (!link_.write(f)) ++write_failures_;
    for (const auto& c : out_.commands) {
      try {
        simulator_.on_setpoint(c);
      } catch (const std::invalid_argument& e) {
        ++command_errors_;
        rt_.status().input_dropped(kLinkChannel, std::string("MAVLink setpoint not flown: ") + e.what());
      }
    }
    if (out_.pong_ts1) pong_ = out_.pong_ts1;
    out_ = sim::VehicleOutput{};
  }

  common::Runtime& rt_;
  sim::MavlinkVehicleOptions o_;
  sim::Simulator& simulator_;
  sim::MavlinkVehicle vehicle_;
  mavlink_bridge::LinkReader link_;
  mavlink::Parser parser_;
  int64_t parser_drops_ = 0;
  std::vector<mavlink_bridge::LinkChunk> chunks_;
  sim::VehicleOutput out_;
  std::optional<Clock::time_point> last_heartbeat_;
  std::optional<int64_t> pong_;
  int64_t write_failures_ = 0;
  int64_t command_errors_ = 0;
};

/// One line on the MAVLink vehicle for the status and the last log line.
std::string mavlink_detail(MavlinkSide& mav, int64_t own_pose_timeouts, int64_t barrier_timeouts) {
  const auto& n = mav.vehicle().counts();
  return fmt::format(
      "autopilot {}: mavlink setpoints {} flown, {} ignored (not engaged), {} refused; offboard lost {}, guided "
      "timeouts {}, engage refused {}; own-pose timeouts {}, barrier timeouts {}, write failures {}",
      mav.vehicle().mode_name(), n.setpoints_applied, n.setpoints_ignored, n.setpoints_refused, n.offboard_lost,
      n.guided_timeouts, n.mode_refusals, own_pose_timeouts, barrier_timeouts, mav.write_failures());
}

int run(common::Runtime& rt, const sim::SimOptions& o, const sim::Scenario& scenario) {
  common::StatusTracker& status = rt.status();
  // The single camera of camera.*, extrinsics.* and output.* (the localizer's from the same keys: their defaults
  // agree), or the cameras of the rig file cameras.rig.
  const std::vector<sim::SimCameraOutput> outputs = sim::sim_cameras(o);
  std::vector<sim::SimCamera> cameras;
  for (const auto& c : outputs) cameras.push_back(c.camera);
  const std::string cameras_note = fmt::format("{} camera{}{}", outputs.size(), outputs.size() == 1 ? "" : "s",
                                               o.camera_rig.empty() ? "" : " (rig " + o.camera_rig + ")");

  // One renderer per camera, all in the first one's GL context (a lens map and render targets per camera).
  std::vector<std::unique_ptr<sim::Renderer>> renderers;
  std::vector<sim::Renderer*> renderer_ptrs;
  if (o.render) {
    try {
      for (const auto& c : cameras) {
        renderers.push_back(renderers.empty()
                                ? std::make_unique<sim::Renderer>(c.model, o.render_options)
                                : std::make_unique<sim::Renderer>(c.model, o.render_options, *renderers.front()));
        renderer_ptrs.push_back(renderers.back().get());
      }
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("cannot render: {} (render.enabled: false runs without images)", e.what()));
    }
    for (const auto& c : outputs) {
      spdlog::info("rendering camera {} ({}x{}) on {} with {}", c.camera.camera_id, c.camera.model.width(),
                   c.camera.model.height(), c.image_channel, renderers.front()->gl_renderer());
    }
  }
  sim::Simulator simulator(scenario, cameras, renderer_ptrs);
  simulator.set_own_pose_error(o.own_pose_error);

  if (o.render) {
    for (const auto& c : outputs) status.declare_output(c.image_channel);
  }
  // The preview is the first camera's.
  camera_driver::PreviewMaker preview(o.preview);
  const std::string preview_channel = o.preview.channel_for(outputs.front().image_channel);
  if (o.render && o.preview.enabled) status.declare_output(preview_channel);
  const bool via_mavlink = o.autopilot == "mavlink";
  if (via_mavlink && rt.input_is_file())
    throw std::runtime_error(
        "autopilot: mavlink needs a live bus (the companion publishes OWN_POSE), not a file input");
  if (!via_mavlink) status.declare_output(o.own_pose_channel);
  std::unique_ptr<MavlinkSide> mav;
  if (via_mavlink) {
    if (!simulator.takes_setpoints())
      throw std::runtime_error(
          "autopilot: mavlink: the scenario's camera vehicle is scripted (control: setpoints needed)");
    mav = std::make_unique<MavlinkSide>(rt, o.mavlink, simulator);
  }
  status.declare_output(o.ground_truth_channel);
  if (o.detections.from_ground_truth) {
    std::vector<std::string> channels;
    for (const auto& c : outputs) {
      status.declare_output(c.detections_channel);
      channels.push_back(c.detections_channel);
    }
    spdlog::warn(
        "detections come from GROUND TRUTH, not from a detector (detections.from_ground_truth: true): "
        "detections_t with source SOURCE_GROUND_TRUTH on {}, {} boxes, edge noise {} px",
        fmt::join(channels, ", "), o.detections.box, o.detections.noise_px);
  }

  const bool lockstep = o.sync.mode == "lockstep" && (simulator.takes_setpoints() || o.sync.scripted_lockstep);
  const bool realtime = o.sync.mode == "realtime";
  int64_t newest_setpoint_utime = -1;
  bool input_ended = false;
  // With autopilot: mavlink the follower's SETPOINT only paces the lockstep (the pipeline has answered a frame): the
  // vehicle flies what comes over MAVLink, and the companion publishes OWN_POSE.
  rt.subscribe<setpoint_t>(o.setpoint_channel, [&](const setpoint_t& sp) {
    if (!via_mavlink) simulator.on_setpoint(sp);
    newest_setpoint_utime = std::max(newest_setpoint_utime, sp.utime);
  });
  // sync.image_by_image: the newest detections_t utime back from each camera's detector (by output index).
  const bool image_by_image =
      lockstep && o.sync.image_by_image && o.render && !o.detections.from_ground_truth && outputs.size() > 1;
  std::vector<int64_t> newest_detections_utime(outputs.size(), -1);
  int64_t image_by_image_timeouts = 0;
  if (image_by_image) {
    for (size_t i = 0; i + 1 < outputs.size(); ++i) {
      const int camera_id = outputs[i].camera.camera_id;
      rt.subscribe<detections_t>(outputs[i].detections_channel, [&, i, camera_id](const detections_t& d) {
        if (d.camera_id == camera_id) newest_detections_utime[i] = std::max(newest_detections_utime[i], d.utime);
      });
    }
  }
  int64_t newest_own_pose_utime = -1;
  if (via_mavlink) {
    rt.subscribe<own_pose_t>(o.own_pose_channel, [&](const own_pose_t& p) {
      newest_own_pose_utime = std::max(newest_own_pose_utime, p.utime);
    });
  }
  // Waits (wall clock, bounded) until done() or the deadline, handling LCM and the MAVLink link meanwhile. False when
  // it timed out or stop was requested.
  auto wait_until = [&](const std::function<bool()>& done, double timeout_s) {
    const auto deadline =
        Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
    for (;;) {
      if (mav) mav->service();
      if (done()) return true;
      if (rt.stop_requested() || Clock::now() >= deadline) return false;
      rt.spin_once(remaining_ms(deadline, 50));
    }
  };

  wait_for_processes(rt, o.sync.wait_for, o.sync.startup_timeout_s);
  if (rt.stop_requested()) return rt.shutdown();
  if (mav) {
    // The companion must have our clock before the first frame (it publishes no own pose without it).
    spdlog::info("autopilot: MAVLink vehicle ({}) on {}, waiting up to {} s for the companion's TIMESYNC",
                 o.mavlink.firmware, o.mavlink.url, o.sync.startup_timeout_s);
    if (!wait_until([&] { return mav->vehicle().counts().timesync_answered > 0; }, o.sync.startup_timeout_s)) {
      if (rt.stop_requested()) return rt.shutdown();
      throw std::runtime_error(
          fmt::format("autopilot: mavlink: no TIMESYNC request from the companion on {} within {} s", o.mavlink.url,
                      o.sync.startup_timeout_s));
    }
  }

  spdlog::info("scenario '{}' ({}): {} frames at {} Hz from utime {}, {} vehicles, {}; sync {}{}", scenario.name,
               scenario.source, simulator.frame_count(), o.camera.rate_hz, scenario.start_utime,
               scenario.vehicles.size(), cameras_note, o.sync.mode,
               o.sync.mode == "lockstep" && !lockstep
                   ? " (the camera vehicle is scripted: nothing to wait for; sync.scripted_lockstep waits anyway)"
                   : "");
  const std::string gt_note = o.detections.from_ground_truth ? "; detections from ground truth" : "";
  status.set_state(status_t::STATE_OK, "scenario " + scenario.name + " starting, " + cameras_note + gt_note);
  rt.publish_heartbeat();

  int64_t lockstep_timeouts = 0;
  int64_t own_pose_timeouts = 0;
  int64_t barrier_timeouts = 0;
  const auto wall_start = Clock::now();
  // Progress: one log line every 10 s of wall clock (logging only: what is published never depends on it).
  common::Progress::Options progress_options;
  progress_options.unit = "frames";
  progress_options.every_s = 10.0;
  progress_options.sink = [](const std::string& line) { spdlog::info("{}", line); };
  common::Progress progress("flight", static_cast<int64_t>(simulator.frame_count()), progress_options);
  std::string stop_reason = "end of scenario";
  while (!simulator.done()) {
    if (rt.stop_requested()) {
      stop_reason = "";
      break;
    }
    const int64_t t_k = simulator.clock().utime(simulator.next_index());
    // realtime: pace by the wall clock; lockstep with a max_speed: no faster than that. Setpoints are taken as
    // they come. Only when frames are published depends on the wall clock, never what they hold.
    const double pace = realtime ? o.sync.speed : (lockstep ? o.sync.max_speed : 0.0);
    if (pace > 0) {
      const auto due = wall_start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(
                                        simulator.clock().seconds_since_start(t_k) / pace));
      while (Clock::now() < due && !rt.stop_requested()) {
        if (mav) mav->service();
        if (input_ended || rt.input_is_file()) {
          std::this_thread::sleep_for(std::chrono::milliseconds(remaining_ms(due, 100)));
        } else if (!rt.spin_once(remaining_ms(due, mav ? 20 : 100)) && !rt.stop_requested()) {
          input_ended = true;
        }
      }
      if (rt.stop_requested()) continue;
    }

    const auto t0 = Clock::now();
    const sim::SimFrame frame = simulator.step();
    if (mav) {
      mav->on_frame_time(frame);  // the autopilot's telemetry of this frame goes to the companion
    } else {
      rt.publish(o.own_pose_channel, frame.own_pose);
    }
    rt.publish(o.ground_truth_channel, frame.truth);
    if (mav && lockstep) {
      // The companion's OWN_POSE of this frame comes before the frame's images and detections, as ours would.
      const int64_t earliest = frame.utime - static_cast<int64_t>(std::llround(0.5e6 / o.camera.rate_hz));
      if (!wait_until([&] { return newest_own_pose_utime >= earliest; }, o.sync.timeout_s)) {
        if (rt.stop_requested()) continue;
        ++own_pose_timeouts;
        status.set_error(
            fmt::format("autopilot: mavlink: no OWN_POSE for frame {} within {} s", frame.index, o.sync.timeout_s));
      }
    }
    // Every camera's image and detections of this frame, before the lockstep wait (once per frame): those exposed at
    // t_k, then each later exposure (cameras.stagger_s) after its own pose and ground truth.
    struct Publish {
      size_t camera;  // index into outputs and frame.cameras
      int exposure;   // -1: t_k (frame.truth), else frame.later[exposure]
      bool opens_it;  // the exposure's first camera: its own pose and ground truth go out before it
    };
    std::vector<Publish> order;
    {
      std::vector<bool> later(outputs.size(), false);
      for (const sim::SimExposure& e : frame.later)
        for (const size_t i : e.camera_indices) later[i] = true;
      for (size_t i = 0; i < outputs.size(); ++i)
        if (!later[i]) order.push_back({i, -1, false});
      for (size_t e = 0; e < frame.later.size(); ++e)
        for (const size_t i : frame.later[e].camera_indices)
          order.push_back({i, static_cast<int>(e), i == frame.later[e].camera_indices.front()});
    }
    for (size_t k = 0; k < order.size(); ++k) {
      const size_t i = order[k].camera;
      const wingman::ground_truth_t& truth = order[k].exposure < 0 ? frame.truth : frame.later[order[k].exposure].truth;
      const sim::SimCameraFrame& view = frame.cameras[i];
      const sim::SimCameraOutput& out = outputs[i];
      if (order[k].opens_it) {
        if (!mav) rt.publish(o.own_pose_channel, frame.later[order[k].exposure].own_pose);  // MAVLink: the companion's
        rt.publish(o.ground_truth_channel, truth);
      }
      if (!view.bgr.empty()) {
        rt.publish(out.image_channel, sim::to_image_message(view.bgr, view.utime, frame.index, view.camera_id));
        if (i == 0) {
          if (const auto p = preview.offer_bgr(view.bgr, view.utime, frame.index, view.camera_id))
            rt.publish(preview_channel, *p);
        }
      }
      if (o.detections.from_ground_truth) {
        rt.publish(out.detections_channel,
                   sim::truth_detections(truth, frame.index, out.camera.model, view.T_cam_to_world, view.camera_id,
                                         o.detections, static_cast<int>(i)));
      }
      if (image_by_image && k + 1 < order.size() && !view.bgr.empty() && !input_ended) {
        // One image on the bus at a time: the next camera's waits for this one's detections.
        if (!wait_until([&] { return newest_detections_utime[i] >= view.utime; }, o.sync.timeout_s) &&
            !rt.stop_requested()) {
          ++image_by_image_timeouts;
          spdlog::warn("frame {} (utime {}): no detections_t from camera {} on {} within {} s ({} so far); going on",
                       frame.index, view.utime, out.camera.camera_id, out.detections_channel, o.sync.timeout_s,
                       image_by_image_timeouts);
          status.set_error(fmt::format("sync.image_by_image: no detections from camera {} for frame {} within {} s",
                                       out.camera.camera_id, frame.index, o.sync.timeout_s));
        }
      }
    }
    status.set_last_processed_seq(frame.index);
    status.record_latency_ms(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    progress.update(frame.index + 1);  // a flight takes minutes: say how far it is

    if (lockstep && !input_ended) {  // wait for this frame's setpoint (utime >= t_k)
      const auto deadline =
          Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(o.sync.timeout_s));
      while (newest_setpoint_utime < frame.utime && !rt.stop_requested()) {
        if (!rt.input_is_file() && Clock::now() >= deadline) {
          ++lockstep_timeouts;
          spdlog::warn(
              "frame {} (utime {}): no SETPOINT with utime >= the frame's within {} s ({} timeouts so far); "
              "going on with the last setpoint",
              frame.index, frame.utime, o.sync.timeout_s, lockstep_timeouts);
          status.set_error(
              fmt::format("lockstep: no setpoint for frame {} within {} s", frame.index, o.sync.timeout_s));
          break;
        }
        if (mav) mav->service();
        if (newest_setpoint_utime >= frame.utime) break;
        if (!rt.spin_once(remaining_ms(deadline, mav ? 20 : 100)) && !rt.stop_requested()) {
          input_ended = true;  // end of a file input: no more setpoints will come
          break;
        }
      }
      if (mav && !rt.stop_requested()) {
        // The barrier: the companion answers our TIMESYNC after it handled the follower's SETPOINT, so what it sent
        // the vehicle for this frame has arrived (UDP on loopback keeps the order) and is flown from this frame on.
        const int64_t ts1 = mav->ping();
        if (!wait_until([&] { return mav->pong() == ts1; }, o.sync.timeout_s) && !rt.stop_requested()) {
          ++barrier_timeouts;
          status.set_error(
              fmt::format("autopilot: mavlink: no TIMESYNC answer from the companion for frame {} within {} s",
                          frame.index, o.sync.timeout_s));
        }
      }
    } else if (!realtime && !rt.input_is_file()) {
      rt.drain();  // free: take whatever setpoints have arrived, never wait
      if (mav) mav->service();
    }

    const auto& c = simulator.setpoint_counts();
    std::string detail = fmt::format(
        "scenario {}: frame {}/{} at {:.3f} s, {}; {} lockstep timeouts; setpoints {} on time, {} late, {} ignored{}",
        scenario.name, frame.index + 1, simulator.frame_count(), simulator.clock().seconds_since_start(frame.utime),
        cameras_note, lockstep_timeouts, c.queued, c.late, c.ignored, gt_note);
    if (mav) detail += "; " + mavlink_detail(*mav, own_pose_timeouts, barrier_timeouts);
    if (image_by_image) detail += fmt::format("; {} image-by-image timeouts", image_by_image_timeouts);
    const bool degraded =
        lockstep_timeouts > 0 || own_pose_timeouts > 0 || barrier_timeouts > 0 || image_by_image_timeouts > 0;
    status.set_state(degraded ? status_t::STATE_DEGRADED : status_t::STATE_OK, detail);
    rt.heartbeat_if_due();
  }

  const double wall_s = std::chrono::duration<double>(Clock::now() - wall_start).count();
  const int64_t frames = simulator.next_index();
  spdlog::info(
      "{} frames in {:.2f} s wall ({:.1f} frames/s, {:.2f}x real time); {} lockstep timeouts; setpoints {} "
      "on time, {} late, {} ignored",
      frames, wall_s, wall_s > 0 ? frames / wall_s : 0.0,
      wall_s > 0 ? simulator.clock().seconds_since_start(simulator.now_utime()) / wall_s : 0.0, lockstep_timeouts,
      simulator.setpoint_counts().queued, simulator.setpoint_counts().late, simulator.setpoint_counts().ignored);
  if (mav) spdlog::info("{}", mavlink_detail(*mav, own_pose_timeouts, barrier_timeouts));
  if (image_by_image)
    spdlog::info("image by image: {} timeouts waiting for a camera's detections", image_by_image_timeouts);
  return rt.shutdown(stop_reason);
}

// The keys of a --render-config file: the renderer's options (render.*), nothing else.
struct RenderConfig {
  sim::RenderOptions render;
  template <class V>
  void visit(V& v) {
    render.visit(v);
  }
  std::vector<std::string> validate() const { return render.validate(); }
};

}  // namespace

int main(int argc, char** argv) {
  const common::ProcessInfo info{
      "sim", "wingman-sim",
      "Simulates a scenario (--scenario FILE, or scenario.file; --duration S: simulate S seconds instead of the "
      "scenario's duration_s; --render-config FILE: the renderer's render.* keys from FILE instead of --config's): "
      "publishes the camera vehicle's images and own pose and the ground truth, and flies the "
      "camera vehicle on SETPOINT"};

  // --scenario FILE, --duration S and --render-config FILE are this process's own options; the rest goes to the
  // common runtime.
  std::optional<std::string> scenario_arg;
  std::optional<std::string> render_config_arg;
  std::optional<double> duration_arg;
  std::vector<char*> args;
  for (int i = 0; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--scenario") {
      if (i + 1 >= argc) {
        std::cerr << info.executable << ": error: --scenario needs a FILE (see --help)" << std::endl;
        return 2;
      }
      scenario_arg = argv[++i];
    } else if (a.rfind("--scenario=", 0) == 0) {
      scenario_arg = a.substr(11);
    } else if (a == "--render-config") {
      if (i + 1 >= argc) {
        std::cerr << info.executable << ": error: --render-config needs a FILE (see --help)" << std::endl;
        return 2;
      }
      render_config_arg = argv[++i];
    } else if (a.rfind("--render-config=", 0) == 0) {
      render_config_arg = a.substr(16);
    } else if (a == "--duration" || a.rfind("--duration=", 0) == 0) {
      const std::string value = a == "--duration" ? (i + 1 < argc ? argv[++i] : "") : a.substr(11);
      char* end = nullptr;
      const double s = std::strtod(value.c_str(), &end);
      if (value.empty() || *end != '\0' || !(s > 0) || !std::isfinite(s)) {
        std::cerr << info.executable << ": error: --duration = '" << value
                  << "': must be a number of simulated seconds > 0 (see --help)" << std::endl;
        return 2;
      }
      duration_arg = s;
    } else {
      args.push_back(argv[i]);
    }
  }

  sim::SimOptions options;
  std::optional<sim::Scenario> scenario;
  // The layered --config files and --set overrides, through the one loader (common/config.hpp), as every process.
  auto load = [&](const common::ConfigSources& sources, bool print) -> std::string {
    if (!sources.empty()) {
      options = common::load_options<sim::SimOptions>(sources);
    } else if (const auto problems = options.validate(); !problems.empty()) {
      throw common::ConfigError("built-in defaults invalid: " + problems.front());
    }
    if (scenario_arg) options.scenario = *scenario_arg;
    if (render_config_arg) {
      // A file of render.* keys only (e.g. the lighting `wingman scenario random` writes for a flight): the renderer's
      // options come from it, its missing keys at their defaults; render.enabled stays as --config sets it.
      options.render_options = common::load_options<RenderConfig>(*render_config_arg).render;
    }
    if (print) {
      return common::print_options(
          options, info.executable + " effective configuration" +
                       (sources.empty() ? " (built-in defaults)" : " (from " + sources.describe() + ")"));
    }
    if (options.scenario.empty()) {
      throw common::ConfigError(
          "no scenario: give --scenario FILE (e.g. config/scenarios/follow_1d.yaml) or "
          "scenario.file in --config");
    }
    // A bad rig file is a configuration error, found before anything starts: exit 2 naming cameras.rig and the file.
    if (!options.camera_rig.empty()) (void)sim::load_sim_rig(options);
    scenario = sim::load_scenario(options.scenario);  // a bad scenario is a configuration error: exit 2
    if (duration_arg) scenario->duration_s = *duration_arg;
    return "";
  };
  return common::run_process_impl(info, static_cast<int>(args.size()), args.data(),
                                  std::function<std::string(const common::ConfigSources&, bool)>(load),
                                  [&](common::Runtime& rt) { return run(rt, options, *scenario); });
}
