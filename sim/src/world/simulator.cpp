// SPDX-License-Identifier: MIT
// The simulator: vehicles, setpoint timing, frames with own pose, ground truth, boxes and images.
#include "wingman/sim/simulator.hpp"

#include "trapezoid.hpp"
#include "wingman/sim/renderer.hpp"
#include "wingman/sim/vehicle_command.hpp"

#include <wingman/common/message_validation.hpp>
#include <wingman/geometry/message_eigen.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

namespace wingman::sim {
namespace {

/// Propeller speed in hover, rad/s (about 5700 rpm, an F450 with 10" props); it scales with sqrt(thrust / hover).
constexpr double kHoverPropRate = 600.0;

}  // namespace

struct Simulator::Vehicle {
  VehicleSpec spec;
  DroneModel model;
  Multirotor body;
  std::unique_ptr<MotionScript> script;  ///< null when the vehicle takes setpoints
  double prop_angle_rad = 0.0;
  double prop_rate_rad_s = kHoverPropRate;

  Vehicle(const VehicleSpec& s, const FrameClock& clock)
      : spec(s), model(DroneModel::from_spec(s.drone)), body(s.dynamics, s.p_initial_in_world, s.yaw_initial_rad) {
    if (s.control == VehicleSpec::Control::kScript) {
      script = make_motion_script(s.motion, s.p_initial_in_world, s.yaw_initial_rad, clock);
      if (script->kinematic()) {
        const MotionReference r = script->at(0.0);
        body.teleport(r.p_in_world, r.yaw_rad);
      }
    }
    // Propellers start at different angles so that drones do not look identical.
    prop_angle_rad =
        2.0 * M_PI * static_cast<double>(detail::mix_seed(static_cast<uint64_t>(s.id), 7) >> 11) * 0x1.0p-53;
  }
};

namespace {

std::vector<SimCamera> checked_cameras(std::vector<SimCamera> cameras) {
  if (cameras.empty()) throw std::invalid_argument("Simulator: no camera");
  if (cameras.size() > 8) throw std::invalid_argument(fmt::format("Simulator: {} cameras, at most 8", cameras.size()));
  for (size_t i = 0; i < cameras.size(); ++i) {
    if (cameras[i].rate_hz != cameras[0].rate_hz)
      throw std::invalid_argument(
          fmt::format("Simulator: camera {} has rate_hz {}, camera {} {}: all cameras expose "
                      "at the same frame times",
                      cameras[i].camera_id, cameras[i].rate_hz, cameras[0].camera_id, cameras[0].rate_hz));
    const double period_s = 1.0 / cameras[0].rate_hz;
    if (!(cameras[i].exposure_offset_s >= 0.0 && cameras[i].exposure_offset_s < period_s))
      throw std::invalid_argument(
          fmt::format("Simulator: camera {} has exposure_offset_s {}: must be in [0, {}) s (within its frame period)",
                      cameras[i].camera_id, cameras[i].exposure_offset_s, period_s));
    for (size_t j = 0; j < i; ++j) {
      if (cameras[j].camera_id == cameras[i].camera_id)
        throw std::invalid_argument(fmt::format("Simulator: two cameras with camera_id {}", cameras[i].camera_id));
    }
  }
  return cameras;
}

std::vector<Renderer*> single(Renderer* renderer) {
  return renderer ? std::vector<Renderer*>{renderer} : std::vector<Renderer*>{};
}

}  // namespace

Simulator::Simulator(Scenario scenario, SimCamera camera, Renderer* renderer)
    : Simulator(std::move(scenario), std::vector<SimCamera>{std::move(camera)}, single(renderer)) {}

Simulator::Simulator(Scenario scenario, std::vector<SimCamera> cameras, std::vector<Renderer*> renderers)
    : scenario_(std::move(scenario)),
      cameras_(checked_cameras(std::move(cameras))),
      renderers_(std::move(renderers)),
      clock_(scenario_.start_utime, cameras_.front().rate_hz) {
  if (!renderers_.empty() && renderers_.size() != cameras_.size())
    throw std::invalid_argument(fmt::format("Simulator: {} renderers for {} cameras (one per camera, or none)",
                                            renderers_.size(), cameras_.size()));
  for (size_t i = 0; i < cameras_.size(); ++i) {
    if (!renderers_.empty() && renderers_[i] == nullptr)
      throw std::invalid_argument(fmt::format("Simulator: renderer {} is null", i));
    projectors_.emplace_back(cameras_[i].model, renderers_.empty() ? 80.0 : renderers_[i]->options().max_half_fov_deg);
  }
  if (scenario_.vehicles.empty()) throw std::invalid_argument("scenario " + scenario_.name + ": no vehicles");
  std::optional<int64_t> last_script_end;
  for (const auto& spec : scenario_.vehicles) {
    try {
      vehicles_.push_back(std::make_unique<Vehicle>(spec, clock_));
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument(fmt::format("scenario {}: vehicle '{}': {}", scenario_.name, spec.name, e.what()));
    }
    Vehicle& v = *vehicles_.back();
    if (spec.id == 0) camera_vehicle_ = &v;
    if (v.script) {
      if (auto end = v.script->end_utime()) last_script_end = std::max(last_script_end.value_or(*end), *end);
    }
  }
  if (!camera_vehicle_) throw std::invalid_argument("scenario " + scenario_.name + ": no vehicle with id 0");
  int64_t end_utime;
  if (scenario_.duration_s > 0) {
    end_utime = scenario_.start_utime + static_cast<int64_t>(std::llround(scenario_.duration_s * 1e6));
  } else if (last_script_end) {
    end_utime = *last_script_end;
  } else {
    throw std::invalid_argument("scenario " + scenario_.name +
                                ": duration_s is 0 (until the scripts end) but no script ends; give a duration");
  }
  frame_count_ = clock_.frames_before(end_utime);
  now_utime_ = scenario_.start_utime;
  command_delay_us_ = static_cast<int64_t>(std::llround(scenario_.command_delay_s * 1e6));
}

Simulator::~Simulator() = default;

bool Simulator::takes_setpoints() const { return camera_vehicle_->spec.control == VehicleSpec::Control::kSetpoints; }

const MultirotorState& Simulator::vehicle_state(int id) const {
  for (const auto& v : vehicles_) {
    if (v->spec.id == id) return v->body.state();
  }
  throw std::out_of_range(fmt::format("scenario {}: no vehicle with id {}", scenario_.name, id));
}

Eigen::Isometry3d Simulator::body_to_world(const MultirotorState& s) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = s.q_body_to_world.toRotationMatrix();
  T.translation() = s.p_body_in_world;
  return T;
}

void Simulator::on_setpoint(const wingman::setpoint_t& setpoint) {
  if (const std::string bad = common::validate_message(setpoint); !bad.empty()) throw std::invalid_argument(bad);
  if (!takes_setpoints()) {
    ++setpoint_counts_.ignored;
    return;
  }
  const VehicleCommand command = command_from_setpoint(setpoint);
  int64_t apply = setpoint.utime + command_delay_us_;
  if (apply < now_utime_) {
    ++setpoint_counts_.late;
    apply = now_utime_;
  } else {
    ++setpoint_counts_.queued;
  }
  pending_.emplace_hint(pending_.upper_bound(apply), apply, command);  // after those of the same time
  apply_due_setpoints();  // a setpoint due now takes effect before the vehicles move on
}

void Simulator::apply_due_setpoints() {
  while (!pending_.empty() && pending_.begin()->first <= now_utime_) {
    camera_vehicle_->body.set_command(pending_.begin()->second);
    pending_.erase(pending_.begin());
  }
}

void Simulator::integrate(Vehicle& v, int64_t from_utime, int64_t to_utime) {
  const double dt = static_cast<double>(to_utime - from_utime) * 1e-6;
  if (dt <= 0) return;
  // Propellers turn at a rate that grows with the square root of the thrust (hover rate at 1 g).
  const MultirotorState& s = v.body.state();
  v.prop_rate_rad_s = kHoverPropRate * std::sqrt(std::max(0.1, (s.a_body_in_world.z() + kGravity) / kGravity));
  v.prop_angle_rad = std::fmod(v.prop_angle_rad + v.prop_rate_rad_s * dt, 2.0 * M_PI);
  if (!v.script) {
    v.body.advance(dt);
    return;
  }
  if (v.script->kinematic()) {
    const MotionReference r = v.script->at(clock_.seconds_since_start(to_utime));
    v.body.teleport(r.p_in_world, r.yaw_rad);
    return;
  }
  // Scripted flight: the reference (with its velocity and acceleration as feed-forward) is re-read every step.
  const int n = std::max(1, static_cast<int>(std::ceil(dt / v.body.limits().step_s - 1e-9)));
  const double h = dt / n;
  const double t0 = clock_.seconds_since_start(from_utime);
  for (int i = 0; i < n; ++i) {
    const MotionReference r = v.script->at(t0 + i * h);
    VehicleCommand c;
    c.mode = VehicleCommand::Mode::kPosition;
    c.p_ref_in_world = r.p_in_world;
    c.v_ref_in_world = r.v_in_world;
    c.a_ref_in_world = r.a_in_world;
    c.yaw_ref_rad = r.yaw_rad;
    v.body.set_command(c);
    v.body.step(h);
  }
}

void Simulator::advance_to(int64_t utime) {
  apply_due_setpoints();
  while (now_utime_ < utime) {
    int64_t next = utime;
    if (!pending_.empty()) next = std::min(next, pending_.begin()->first);
    for (auto& v : vehicles_) integrate(*v, now_utime_, next);
    now_utime_ = next;
    apply_due_setpoints();
  }
}

void Simulator::set_own_pose_error(const OwnPoseErrorOptions& options) {
  if (options.enabled())
    own_pose_error_.emplace(options);
  else
    own_pose_error_.reset();
}

void Simulator::expose(int64_t frame_index, const std::vector<size_t>& indices, wingman::own_pose_t& own_pose,
                       MultirotorState& own_reported, wingman::ground_truth_t& truth,
                       std::vector<SimCameraFrame>& views) {
  const int64_t utime = now_utime_;
  const MultirotorState& own = camera_vehicle_->body.state();
  own_reported = own_pose_error_ ? own_pose_error_->reported(own, utime) : own;
  own_pose.utime = utime;
  own_pose.frame = wingman::own_pose_t::FRAME_ENU;
  geometry::to_array(own_reported.p_body_in_world, own_pose.p_body_in_world);
  geometry::to_array(own_reported.q_body_to_world, own_pose.q_body_to_world);
  geometry::to_array(own_reported.v_body_in_world, own_pose.v_body_in_world);
  if (own_pose_error_ && own_pose_error_->options().report_covariance) {
    const double var_p = std::pow(own_pose_error_->options().position_std_m, 2);
    const double var_a = std::pow(own_pose_error_->options().attitude_std_rad, 2);
    own_pose.has_covariance = true;
    own_pose.cov_p_body_in_world[0] = own_pose.cov_p_body_in_world[3] = own_pose.cov_p_body_in_world[5] = var_p;
    for (double& v : own_pose.var_rpy_body) v = var_a;
  }

  truth.utime = utime;
  truth.frame = wingman::own_pose_t::FRAME_ENU;
  truth.image_seq = renderers_.empty() ? -1 : frame_index;
  std::vector<DroneInstance> targets;
  for (const auto& v : vehicles_) {
    const MultirotorState& st = v->body.state();
    wingman::vehicle_truth_t t{};
    t.vehicle_id = v->spec.id;
    t.name = v->spec.name;
    geometry::to_array(st.p_body_in_world, t.p_body_in_world);
    geometry::to_array(st.q_body_to_world, t.q_body_to_world);
    geometry::to_array(st.v_body_in_world, t.v_body_in_world);
    geometry::to_array(st.w_body_in_body, t.w_body_in_body);
    t.bounding_radius = v->model.bounding_radius();
    truth.vehicles.push_back(t);
    if (v.get() == camera_vehicle_) continue;
    DroneInstance d;
    d.vehicle_id = v->spec.id;
    d.model = &v->model;
    d.T_body_to_world = body_to_world(st);
    d.v_body_in_world = st.v_body_in_world;
    d.w_body_in_body = st.w_body_in_body;
    d.prop_angle_rad = v->prop_angle_rad;
    d.prop_rate_rad_s = v->prop_rate_rad_s;
    targets.push_back(d);
  }
  truth.num_vehicles = static_cast<int32_t>(truth.vehicles.size());

  // The cameras of this exposure from the same body pose, each through its mount and lens.
  const Eigen::Isometry3d T_body_to_world = body_to_world(own);
  const uint64_t frame_seed = detail::mix_seed(scenario_.seed, static_cast<uint64_t>(frame_index));
  for (const size_t i : indices) {
    const SimCamera& camera = cameras_[i];
    SimCameraFrame& view = views[i];
    view.camera_id = camera.camera_id;
    view.utime = utime;
    Eigen::Isometry3d T_cam_to_body = Eigen::Isometry3d::Identity();
    T_cam_to_body.linear() = camera.mount.R_cam_to_body;
    T_cam_to_body.translation() = camera.mount.p_cam_in_body;
    view.T_cam_to_world = T_body_to_world * T_cam_to_body;

    std::vector<RenderedBox> boxes;
    if (!renderers_.empty()) {
      CameraMotion motion;
      motion.v_cam_in_world = own.v_body_in_world;
      motion.w_cam_in_cam = camera.mount.R_cam_to_body.transpose() * own.w_body_in_body;
      // The first camera keeps the single camera's seed; the others get their own noise and exposure jitter.
      const uint64_t camera_seed = i == 0 ? frame_seed : detail::mix_seed(frame_seed, i);
      RenderResult r = renderers_[i]->render(view.T_cam_to_world, targets, utime, camera_seed, motion);
      view.bgr = std::move(r.bgr);
      boxes = std::move(r.boxes);
    } else {
      for (const auto& d : targets) {
        boxes.push_back(
            projectors_[i].project(*d.model, view.T_cam_to_world, d.T_body_to_world, d.prop_angle_rad, d.vehicle_id));
      }
    }
    for (const auto& b : boxes) {
      wingman::truth_box_t t{};
      t.vehicle_id = b.vehicle_id;
      t.camera_id = camera.camera_id;
      t.cx = static_cast<float>(b.cx);
      t.cy = static_cast<float>(b.cy);
      t.w = static_cast<float>(b.w);
      t.h = static_cast<float>(b.h);
      t.visible = b.visible;
      t.range = b.range_m;
      truth.boxes.push_back(t);
    }
  }
  truth.num_boxes = static_cast<int32_t>(truth.boxes.size());
}

SimFrame Simulator::step() {
  if (done()) {
    throw std::logic_error(fmt::format("scenario {}: step() after the last frame ({})", scenario_.name, frame_count_));
  }
  SimFrame f;
  f.index = next_index_++;
  f.utime = clock_.utime(f.index);
  f.cameras.resize(cameras_.size());
  advance_to(f.utime);
  // The cameras by exposure offset (microseconds): those at t_k first, in the simulator's order within each.
  std::map<int64_t, std::vector<size_t>> by_offset;
  for (size_t i = 0; i < cameras_.size(); ++i)
    by_offset[std::llround(cameras_[i].exposure_offset_s * 1e6)].push_back(i);
  const auto at_tk = by_offset.find(0);
  expose(f.index, at_tk == by_offset.end() ? std::vector<size_t>{} : at_tk->second, f.own_pose, f.own_reported, f.truth,
         f.cameras);
  for (const auto& [offset_us, indices] : by_offset) {
    if (offset_us == 0) continue;
    advance_to(f.utime + offset_us);
    SimExposure e;
    e.utime = now_utime_;
    e.camera_indices = indices;
    expose(f.index, indices, e.own_pose, e.own_reported, e.truth, f.cameras);
    f.later.push_back(std::move(e));
  }
  f.bgr = f.cameras.front().bgr;
  f.T_cam_to_world = f.cameras.front().T_cam_to_world;
  return f;
}

wingman::image_t to_image_message(const cv::Mat& bgr, int64_t utime, int64_t seq, int32_t camera_id) {
  if (bgr.type() != CV_8UC3 || bgr.empty()) throw std::invalid_argument("to_image_message: expected a CV_8UC3 image");
  wingman::image_t m{};
  m.utime = utime;
  m.seq = seq;
  m.camera_id = camera_id;
  m.width = bgr.cols;
  m.height = bgr.rows;
  m.stride = 3 * bgr.cols;
  m.pixel_format = wingman::image_t::BGR8;
  m.size = m.stride * m.height;
  m.data.resize(static_cast<size_t>(m.size));
  for (int y = 0; y < bgr.rows; ++y) {
    std::copy_n(bgr.ptr<uint8_t>(y), m.stride, m.data.data() + static_cast<size_t>(y) * m.stride);
  }
  return m;
}

}  // namespace wingman::sim
