// SPDX-License-Identifier: MIT
// wingman-sim: flies a scenario and publishes what the camera vehicle's camera and autopilot would (images, own pose)
// plus ground truth; takes the follower's setpoints; advances simulated time by messages (lockstep), freely or in
// real time.
#include "wingman/sim/renderer.hpp"
#include "wingman/sim/scenario.hpp"
#include "wingman/sim/sim_options.hpp"
#include "wingman/sim/simulator.hpp"
#include "wingman/sim/truth_detections.hpp"

#include <wingman/common/runtime.hpp>
#include <wingman/localizer/calibration.hpp>

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <thread>

namespace {

using namespace wingman;
using Clock = std::chrono::steady_clock;
namespace common = wingman::common;

localizer::CameraModel make_camera(const sim::SimCameraOptions& o) {
  if (o.calibration.empty()) {
    // The localizer's built-in camera: principal point at the image centre (pixel centres at integers).
    return localizer::CameraModel::pinhole(o.width, o.height, o.focal_px, o.focal_px, 0.5 * o.width - 0.5,
                                           0.5 * o.height - 0.5);
  }
  return localizer::load_calibration(o.calibration, o.kalibr_camera);
}

int remaining_ms(Clock::time_point deadline, int cap_ms) {
  const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now()).count();
  return static_cast<int>(std::clamp<int64_t>(left, 0, cap_ms));
}

/// Waits until every instance of `names` has published a heartbeat (bounded by timeout_s of wall clock).
void wait_for_processes(common::Runtime& rt, const std::vector<std::string>& names, double timeout_s) {
  if (names.empty()) return;
  // The subscriptions outlive this function (heartbeats keep coming): they share the map.
  auto seen_ptr = std::make_shared<std::map<std::string, bool>>();
  auto& seen = *seen_ptr;
  for (const auto& name : names) {
    seen[name] = false;
    rt.subscribe<status_t>(common::status_channel(name),
                           [seen_ptr, name](const status_t&) { (*seen_ptr)[name] = true; });
  }
  spdlog::info("waiting up to {} s for the status of: {}", timeout_s, fmt::join(names, ", "));
  const auto deadline =
      Clock::now() + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(timeout_s));
  auto missing = [&] {
    std::vector<std::string> m;
    for (const auto& [name, ok] : seen) {
      if (!ok) m.push_back(name + " (" + common::status_channel(name) + ")");
    }
    return m;
  };
  while (!missing().empty() && Clock::now() < deadline && !rt.stop_requested()) {
    if (!rt.spin_once(remaining_ms(deadline, 100)) && !rt.stop_requested()) break;  // end of a file input
  }
  if (rt.stop_requested()) return;
  if (const auto m = missing(); !m.empty()) {
    throw std::runtime_error(
        fmt::format("sync.wait_for: no status heartbeat within {} s from {}", timeout_s, fmt::join(m, ", ")));
  }
}

int run(common::Runtime& rt, const sim::SimOptions& o, const sim::Scenario& scenario) {
  common::StatusTracker& status = rt.status();
  sim::SimCamera camera{make_camera(o.camera), localizer::Extrinsics::from_options(o.extrinsics), o.camera.rate_hz,
                        o.camera.camera_id};

  std::unique_ptr<sim::Renderer> renderer;
  if (o.render) {
    try {
      renderer = std::make_unique<sim::Renderer>(camera.model, o.render_options);
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("cannot render: {} (render.enabled: false runs without images)", e.what()));
    }
    spdlog::info("rendering {}x{} with {}", camera.model.width(), camera.model.height(), renderer->gl_renderer());
  }
  sim::Simulator simulator(scenario, camera, renderer.get());

  if (o.render) status.declare_output(o.image_channel);
  status.declare_output(o.own_pose_channel);
  status.declare_output(o.ground_truth_channel);
  if (o.detections.from_ground_truth) {
    status.declare_output(o.detections_channel);
    spdlog::warn(
        "detections come from GROUND TRUTH, not from a detector (detections.from_ground_truth: true): "
        "detections_t with source SOURCE_GROUND_TRUTH on {}, {} boxes, edge noise {} px",
        o.detections_channel, o.detections.box, o.detections.noise_px);
  }

  const bool lockstep = o.sync.mode == "lockstep" && simulator.takes_setpoints();
  const bool realtime = o.sync.mode == "realtime";
  int64_t newest_setpoint_utime = -1;
  bool input_ended = false;
  rt.subscribe<setpoint_t>(o.setpoint_channel, [&](const setpoint_t& sp) {
    simulator.on_setpoint(sp);
    newest_setpoint_utime = std::max(newest_setpoint_utime, sp.utime);
  });

  wait_for_processes(rt, o.sync.wait_for, o.sync.startup_timeout_s);
  if (rt.stop_requested()) return rt.shutdown();

  spdlog::info("scenario '{}' ({}): {} frames at {} Hz from utime {}, {} vehicles; sync {}{}", scenario.name,
               scenario.source, simulator.frame_count(), o.camera.rate_hz, scenario.start_utime,
               scenario.vehicles.size(), o.sync.mode,
               o.sync.mode == "lockstep" && !lockstep ? " (the camera vehicle is scripted: nothing to wait for)" : "");
  const std::string gt_note = o.detections.from_ground_truth ? "; detections from ground truth" : "";
  status.set_state(status_t::STATE_OK, "scenario " + scenario.name + " starting" + gt_note);
  rt.publish_heartbeat();

  int64_t lockstep_timeouts = 0;
  const auto wall_start = Clock::now();
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
        if (input_ended || rt.input_is_file()) {
          std::this_thread::sleep_for(std::chrono::milliseconds(remaining_ms(due, 100)));
        } else if (!rt.spin_once(remaining_ms(due, 100)) && !rt.stop_requested()) {
          input_ended = true;
        }
      }
      if (rt.stop_requested()) continue;
    }

    const auto t0 = Clock::now();
    const sim::SimFrame frame = simulator.step();
    rt.publish(o.own_pose_channel, frame.own_pose);
    rt.publish(o.ground_truth_channel, frame.truth);
    if (!frame.bgr.empty()) {
      rt.publish(o.image_channel, sim::to_image_message(frame.bgr, frame.utime, frame.index, camera.camera_id));
    }
    if (o.detections.from_ground_truth) {
      rt.publish(o.detections_channel, sim::truth_detections(frame.truth, frame.index, camera.model,
                                                             frame.T_cam_to_world, camera.camera_id, o.detections));
    }
    status.set_last_processed_seq(frame.index);
    status.record_latency_ms(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());

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
        if (!rt.spin_once(remaining_ms(deadline, 100)) && !rt.stop_requested()) {
          input_ended = true;  // end of a file input: no more setpoints will come
          break;
        }
      }
    } else if (!realtime && !rt.input_is_file()) {
      rt.drain();  // free: take whatever setpoints have arrived, never wait
    }

    const auto& c = simulator.setpoint_counts();
    const std::string detail = fmt::format(
        "scenario {}: frame {}/{} at {:.3f} s; {} lockstep timeouts; setpoints {} on time, {} late, {} ignored{}",
        scenario.name, frame.index + 1, simulator.frame_count(), simulator.clock().seconds_since_start(frame.utime),
        lockstep_timeouts, c.queued, c.late, c.ignored, gt_note);
    status.set_state(lockstep_timeouts > 0 ? status_t::STATE_DEGRADED : status_t::STATE_OK, detail);
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
  auto load = [&](const std::string& path, bool print) -> std::string {
    if (!path.empty()) {
      options = common::load_options<sim::SimOptions>(path);
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
      return common::print_options(options, info.executable + " effective configuration" +
                                                (path.empty() ? " (built-in defaults)" : " (from " + path + ")"));
    }
    if (options.scenario.empty()) {
      throw common::ConfigError(
          "no scenario: give --scenario FILE (e.g. config/scenarios/follow_1d.yaml) or "
          "scenario.file in --config");
    }
    scenario = sim::load_scenario(options.scenario);  // a bad scenario is a configuration error: exit 2
    if (duration_arg) scenario->duration_s = *duration_arg;
    return "";
  };
  return common::run_process_impl(info, static_cast<int>(args.size()), args.data(), load,
                                  [&](common::Runtime& rt) { return run(rt, options, *scenario); });
}
