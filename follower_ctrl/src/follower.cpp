// SPDX-License-Identifier: MIT
// The follower's logic: hold rules around the two controllers.
#include "wingman/follower_ctrl/follower.hpp"

#include "setpoint_message.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::follower_ctrl {
namespace {

const FollowerOptions& checked(const FollowerOptions& o) {
  const auto problems = o.validate();
  if (!problems.empty()) {
    std::string all = "invalid FollowerOptions:";
    for (const auto& q : problems) all += " " + q + ";";
    throw std::invalid_argument(all);
  }
  return o;
}

// now - stamp in seconds, for messages: exact enough and defined for hostile times (no int64_t overflow).
double seconds_between(int64_t stamp, int64_t now) {
  return static_cast<double>(static_cast<long double>(now) - static_cast<long double>(stamp)) * 1e-6;
}

const char* source_name(int8_t source) {
  return source == wingman::detections_t::SOURCE_GROUND_TRUTH ? "ground-truth boxes" : "CNN boxes";
}

bool known_source(int8_t source) {
  return source == wingman::detections_t::SOURCE_CNN || source == wingman::detections_t::SOURCE_GROUND_TRUTH;
}

}  // namespace

Follower::Follower(const FollowerOptions& options)
    : options_(checked(options)),
      mode_(options.controller_mode()),
      timeout_us_(options.hold_timeout_us()),
      max_ahead_us_(options.time.max_ahead_us()),
      clock_(options.time),
      own_pose_input_(clock_.add_input("own_pose_t.utime", "own pose", true)),
      driving_input_(mode_ == ControllerMode::kFormation
                         ? clock_.add_input("targets_t.utime", "targets_t", false)
                         : clock_.add_input("detections_t.utime", "detections_t", false)),
      select_policy_(*parse_select_policy(options.formation.select)),
      formation_(options.formation, options.limits, options.camera_mount.rotation()),
      pid_1d_(options.pid_1d, options.limits, options.camera_mount.rotation()),
      localizer_timeout_us_(options.localizer_heartbeat_timeout_us()) {}

void Follower::saw_message_time() {
  // A heartbeat that came before any message time is dated by the first one.
  if (localizer_armed_ && !localizer_seen_utime_) localizer_seen_utime_ = clock_.now();
}

void Follower::admit(int input, int64_t utime, FollowerOutput& out) {
  const common::TimeAdmission a = clock_.admit(input, utime);
  if (!a.accepted()) throw std::invalid_argument(a.problem);
  if (a.resynced()) {
    forget_time_state();
    out.notes.push_back(a.problem);
  }
}

void Follower::forget_time_state() {
  own_.reset();
  first_pose_utime_.reset();
  last_driving_utime_.reset();
  followed_track_id_ = 0;
  followed_since_utime_ = 0;
  last_target_.reset();
  last_box_utime_.reset();
  formation_.reset();
  pid_1d_.reset();
  // The localizer's last sign of life is dated anew by the re-anchored clock (its state is kept).
  if (localizer_seen_utime_) localizer_seen_utime_ = clock_.now();
}

void Follower::on_localizer_status(const wingman::status_t& status) {
  if (mode_ != ControllerMode::kFormation || options_.localizer_instance.empty()) return;
  localizer_armed_ = true;
  localizer_state_ = status.state;
  localizer_detail_ = status.detail;
  if (clock_.now()) localizer_seen_utime_ = clock_.now();
}

std::string Follower::localizer_problem(int64_t utime) const {
  if (mode_ != ControllerMode::kFormation || options_.localizer_instance.empty() || !localizer_armed_) return "";
  if (localizer_state_ == wingman::status_t::STATE_STOPPING || localizer_state_ == wingman::status_t::STATE_ERROR)
    return fmt::format("localizer '{}' reports {}{}", options_.localizer_instance,
                       localizer_state_ == wingman::status_t::STATE_STOPPING ? "STOPPING" : "ERROR",
                       localizer_detail_.empty() ? "" : " (" + localizer_detail_ + ")");
  if (localizer_seen_utime_ && !common::is_fresh(utime, *localizer_seen_utime_, localizer_timeout_us_, max_ahead_us_))
    return fmt::format(
        "no heartbeat from localizer '{}' for {:.3f} s of message time "
        "(localizer.heartbeat_timeout_s = {})",
        options_.localizer_instance, seconds_between(*localizer_seen_utime_, utime),
        options_.localizer_heartbeat_timeout_s);
  return "";
}

FollowerOutput Follower::on_own_pose(const wingman::own_pose_t& pose) {
  FollowerOutput out;
  admit(own_pose_input_, pose.utime, out);
  own_ = own_state_from_message(pose);
  saw_message_time();
  if (!first_pose_utime_) {
    first_pose_utime_ = pose.utime;
    start_height_m_ = own_->p_body_in_world.z();
  }
  const int64_t since = last_driving_utime_.value_or(*first_pose_utime_);
  // A driving input dated after this pose by more than time.max_ahead_s is no sign of life either.
  if (!common::is_fresh(pose.utime, since, timeout_us_, max_ahead_us_)) {
    const bool formation = mode_ == ControllerMode::kFormation;
    out.setpoint = hold(pose.utime, fmt::format("no {} on {} for {:.3f} s of own-pose time (hold.timeout_s = {})",
                                                formation ? "targets_t" : "detections_t",
                                                formation ? options_.targets_channel : options_.detections_channel,
                                                seconds_between(since, pose.utime), options_.hold_timeout_s));
  } else if (const std::string why = localizer_problem(pose.utime); !why.empty()) {
    out.setpoint = hold(pose.utime, why);
  }
  return out;
}

FollowerOutput Follower::on_targets(const wingman::targets_t& msg) {
  if (mode_ != ControllerMode::kFormation)
    throw std::logic_error("Follower::on_targets called in controller.mode pid_1d");
  for (size_t i = 0; i < msg.targets.size(); ++i) {
    if (!known_source(msg.targets[i].detection_source))
      throw std::invalid_argument(
          fmt::format("targets_t.targets[{}].detection_source = {}: must be SOURCE_CNN (0) "
                      "or SOURCE_GROUND_TRUTH (1)",
                      i, msg.targets[i].detection_source));
  }
  FollowerOutput out;
  admit(driving_input_, msg.utime, out);
  last_driving_utime_ = msg.utime;
  saw_message_time();
  if (const std::string why = own_pose_problem(msg.utime); !why.empty()) {
    out.setpoint = hold(msg.utime, why);
    return out;
  }
  if (const std::string why = localizer_problem(msg.utime); !why.empty()) {
    out.setpoint = hold(msg.utime, why);
    return out;
  }
  // A targets_t is the localizer's output: as good a sign of life as a heartbeat (see the class comment).
  if (localizer_armed_) localizer_seen_utime_ = msg.utime;
  const OwnState own = own_->predicted_to(msg.utime);
  const std::vector<TargetState> usable = usable_targets(msg, timeout_us_);
  std::optional<TargetState> chosen = select_target(usable, followed_track_id_, select_policy_, own.p_body_in_world);
  // Another track than the one that has gone is taken only after a wait since its newest image: as long as it was
  // followed, at most formation.reselect_after_s.
  std::string waiting;
  if (chosen && last_target_ && chosen->track_id != followed_track_id_) {
    const double followed_s = seconds_between(followed_since_utime_, last_target_->source_utime);
    const double wait_s = std::min(options_.formation.reselect_after_s, followed_s);
    if (seconds_between(last_target_->source_utime, msg.utime) < wait_s) {
      waiting = fmt::format(
          "; not switching to track {} for {:.3f} s after track {}'s last image (as long as it was followed, at most "
          "formation.reselect_after_s = {})",
          chosen->track_id, wait_s, followed_track_id_, options_.formation.reselect_after_s);
      chosen.reset();
    }
  }
  TargetState target;
  std::string detail;
  if (chosen) {
    if (chosen->track_id != followed_track_id_) {  // a track switch, or the first track
      formation_.reset_pid();
      followed_since_utime_ = chosen->source_utime;
    }
    followed_track_id_ = chosen->track_id;
    last_target_ = *chosen;
    last_source_ = chosen->detection_source;
    target = chosen->predicted_to(msg.utime);
    detail = fmt::format("following track {} on {}", followed_track_id_, source_name(target.detection_source));
  } else if (last_target_ && common::is_fresh(msg.utime, last_target_->source_utime, timeout_us_)) {
    target = last_target_->predicted_to(msg.utime);
    detail = fmt::format("coasting on track {}: no usable update, newest image {:.3f} s old{}", followed_track_id_,
                         seconds_between(last_target_->source_utime, msg.utime), waiting);
  } else {
    const std::string why =
        last_target_
            ? fmt::format("target lost: track {} not seen for {:.3f} s (hold.timeout_s = {}){}", followed_track_id_,
                          seconds_between(last_target_->source_utime, msg.utime), options_.hold_timeout_s, waiting)
            : std::string("no usable target yet (world-frame targets with an image within hold.timeout_s)");
    out.setpoint = hold(msg.utime, why);  // the lost track is remembered: a later hold still names it
    return out;
  }
  const VelocityCommand cmd = formation_.update(target, own, msg.utime, start_height_m_);
  if (cmd.avoiding)
    detail += fmt::format(", avoiding: target {:.2f} m away (formation.avoid_radius_m = {})",
                          (target.p_target_in_world - own.p_body_in_world).norm(), options_.formation.avoid_radius_m);
  out.setpoint = fly(msg.utime, cmd, followed_track_id_, target.detection_source, detail);
  return out;
}

FollowerOutput Follower::on_detections(const wingman::detections_t& msg) {
  if (mode_ != ControllerMode::kPid1d)
    throw std::logic_error("Follower::on_detections called in controller.mode formation");
  if (!known_source(msg.source))
    throw std::invalid_argument(
        fmt::format("detections_t.source = {}: must be SOURCE_CNN (0) or SOURCE_GROUND_TRUTH (1)", msg.source));
  FollowerOutput out;
  admit(driving_input_, msg.utime, out);
  last_driving_utime_ = msg.utime;
  saw_message_time();
  last_source_ = msg.source;
  for (size_t i = 0; i < msg.detections.size(); ++i) {
    const float cx = msg.detections[i].cx;
    if (!(cx >= 0 && cx <= static_cast<float>(msg.image_width)))
      out.rejections.push_back(
          fmt::format("detections_t.detections[{}].cx = {}: outside the image [0, {}]", i, cx, msg.image_width));
  }
  if (const std::string why = own_pose_problem(msg.utime); !why.empty()) {
    out.setpoint = hold(msg.utime, why);
    return out;
  }
  const OwnState own = own_->predicted_to(msg.utime);
  const std::optional<wingman::detection_t> box = most_confident_box(msg);
  if (box) last_box_utime_ = msg.utime;
  if (!last_box_utime_ || !common::is_fresh(msg.utime, *last_box_utime_, timeout_us_)) {
    out.setpoint = hold(
        msg.utime, last_box_utime_ ? fmt::format("target lost: no box for {:.3f} s (hold.timeout_s = {})",
                                                 seconds_between(*last_box_utime_, msg.utime), options_.hold_timeout_s)
                                   : std::string("no box yet"));
    return out;
  }
  const std::optional<Eigen::Vector3d> axis = pid_1d_.axis_in_world(own);
  if (!axis) {
    out.setpoint =
        hold(msg.utime, "pid_1d.axis camera_right: the camera's x axis is vertical in the world (no horizontal axis)");
    return out;
  }
  std::optional<double> error;
  if (box) error = box_centre_error(*box, msg.image_width);
  const Pid1dCommand cmd = pid_1d_.update(error, *axis, own, msg.utime, start_height_m_);
  const std::string detail =
      error ? fmt::format("following the most confident box (e = {:+.3f}) on {}", *error, source_name(msg.source))
            : fmt::format("no box for {:.3f} s: 0 along the axis, height held",
                          seconds_between(*last_box_utime_, msg.utime));
  out.setpoint = fly(msg.utime, cmd.command, 0, msg.source, detail);
  return out;
}

std::string Follower::own_pose_problem(int64_t utime) const {
  if (!own_) return "no own pose yet";
  if (!common::is_fresh(utime, own_->utime, timeout_us_, max_ahead_us_)) {
    if (own_->utime > utime)  // a negative age is stale, not fresh
      return fmt::format("own pose from the future: newest is {:.3f} s after the input (time.max_ahead_s = {})",
                         seconds_between(utime, own_->utime), options_.time.max_ahead_s);
    return fmt::format("own pose stale: newest is {:.3f} s older than the input (hold.timeout_s = {})",
                       seconds_between(own_->utime, utime), options_.hold_timeout_s);
  }
  return "";
}

wingman::setpoint_t Follower::hold(int64_t utime, const std::string& reason) {
  formation_.reset();
  pid_1d_.reset();
  status_.flying = false;
  status_.detail = "holding: " + reason;
  return detail::hold_setpoint(utime, own_ ? &*own_ : nullptr, last_source_);
}

wingman::setpoint_t Follower::fly(int64_t utime, const VelocityCommand& command, int32_t track_id, int8_t source,
                                  const std::string& what) {
  // Finite but extreme inputs (e.g. positions of 1e300 m, found by fuzzing) can overflow the controller: never fly
  // on a non-finite command.
  if (!command.v_body_in_world.allFinite() || !std::isfinite(command.yaw_rate_radps) || !std::isfinite(command.yaw_rad))
    return hold(utime, "controller output is not finite (inputs out of range)");
  status_.flying = true;
  status_.detail = what;
  return detail::velocity_setpoint(utime, own_->frame, command, track_id, source);
}

}  // namespace wingman::follower_ctrl
