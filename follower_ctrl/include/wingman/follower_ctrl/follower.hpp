// SPDX-License-Identifier: MIT
// The follower's logic without LCM: own poses and driving inputs in, one setpoint per driving input out,
// with the hold rules.
#pragma once

#include "wingman/follower_ctrl/follower_options.hpp"
#include "wingman/follower_ctrl/formation_controller.hpp"
#include "wingman/follower_ctrl/pid_1d_controller.hpp"
#include "wingman/follower_ctrl/target_selection.hpp"
#include "wingman/follower_ctrl/world_frame.hpp"

#include <wingman/common/time_sanity.hpp>
#include <wingman/detections_t.hpp>
#include <wingman/own_pose_t.hpp>
#include <wingman/setpoint_t.hpp>
#include <wingman/status_t.hpp>
#include <wingman/targets_t.hpp>

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace wingman::follower_ctrl {

/// What the follower is doing, for the status heartbeat.
struct FollowerStatus {
  bool flying = false;  ///< true: the last setpoint was MODE_VELOCITY; false: holding (or nothing published yet)
  std::string detail = "waiting for inputs";  ///< one line: what it follows, or why it holds
};

/// What one input gave.
struct FollowerOutput {
  /// The setpoint to publish: always one for a driving input (targets_t in mode formation,
  /// detections_t in mode pid_1d); for an own pose only the lost-input hold.
  std::optional<wingman::setpoint_t> setpoint;
  /// Parts of the input that could not be used, one line each naming the field (counted as drops).
  std::vector<std::string> rejections;
  /// Lines for the log that are not drops: a time resync (the input re-anchored the follower's clock).
  std::vector<std::string> notes;
};

/// The follower process's logic. Time is message time only (utimes); the same inputs in the same
/// order give the same setpoints.
///
/// Driving inputs are targets_t (mode formation) or detections_t (mode pid_1d). Each gives exactly
/// one setpoint with the input's utime: MODE_VELOCITY from the mode's controller, or MODE_HOLD when
///  - no own pose has arrived yet, or the newest is more than hold.timeout_s older than the input;
///  - no usable target: none yet, or none for longer than hold.timeout_s (input utime minus the
///    source_utime of the last usable target, resp. the utime of the last detections with a box).
/// Within the timeout, without a usable target in the input:
///  - formation coasts on the last target's constant-velocity prediction (the tracker's model);
///  - pid_1d commands 0 along its axis (ramped by the acceleration limit), height still held.
/// Formation keeps the followed track while the localizer reports it; once it has gone, another track is chosen
/// (formation.select) only after a wait from the gone track's newest image: as long as that track was followed (its
/// images), at most formation.reselect_after_s. Until then the follower coasts and holds as above (the detail names
/// the track it does not switch to) and takes the followed track back when it is reported again (the tracker gives a
/// re-acquired target its old id).
/// Own poses: when no driving input has arrived for longer than hold.timeout_s of own-pose time
/// (counted from the first own pose when none has arrived yet), each own pose gives one MODE_HOLD
/// with its utime, so a stopped localizer or detector cannot leave the follower flying.
/// Localizer watchdog (mode formation, localizer.instance not ""): once a localizer heartbeat
/// (status_t) has arrived, the follower also holds while the localizer is down:
///  - its newest heartbeat reports STATE_STOPPING or STATE_ERROR, or
///  - no heartbeat for longer than localizer.heartbeat_timeout_s of message time: the follower's
///    newest own-pose/targets utime when it arrives is the heartbeat's time (never the receive clock
///    or the heartbeat's wall-clock utime), and later inputs compare their utime with it. A targets_t
///    accepted while the localizer is not STOPPING/ERROR counts as a heartbeat at its utime: heartbeats
///    come once per second of wall time, so a simulation or replay running faster than real time would
///    otherwise see gaps of several seconds of message time between them while targets flow.
/// Then each targets_t gives a MODE_HOLD, and so does each own pose. The next heartbeat in another
/// state ends it; the follower resumes with the next usable target. Before the first heartbeat the
/// watchdog is not armed (no targets come without a localizer, and the targets timeout holds).
/// Time sanity (common::StageClock, options.time): own poses and driving inputs are admitted by one clock of
/// message time. A message dated more than time.max_ahead_s after the newest accepted one is dropped (thrown as
/// std::invalid_argument naming the field), never adopted as "now"; own poses must be strictly after the previous
/// own pose, driving inputs at or after the previous one. Ages are checked both ways: an own pose dated more than
/// time.max_ahead_s after the input, a last driving input after the own pose, a target's image (source_utime) or
/// box after the input are stale, not fresh. When one input's messages have all been refused for
/// time.resync_after_s of their own time (a bad first message latched the order), the clock re-anchors on them and
/// the follower forgets its time-keyed state as at start-up (own pose, targets, PID memory; FollowerOutput::notes
/// says so): it holds until fresh data comes, and recovers within time.resync_after_s after any single bad message.
/// Every hold forgets the PID memory and the previous command; a track switch forgets the PID memory.
/// setpoint_t.detection_source is copied from the data behind the setpoint (the followed target, the
/// detections message; for a hold the newest known); target_track_id is the followed track (0 for pid_1d and holds).
class Follower {
 public:
  /// Throws std::invalid_argument listing options.validate() problems.
  explicit Follower(const FollowerOptions& options);

  /// An own pose (ENU or NED). Throws std::invalid_argument naming the field when its utime is not
  /// after the previous own pose's (duplicate or out of order) or too far ahead (time.max_ahead_s); the caller
  /// drops and counts it.
  FollowerOutput on_own_pose(const wingman::own_pose_t& pose);
  /// A targets_t (mode formation). Throws std::invalid_argument naming the field for a message before
  /// the previous one, or a target with an unknown detection_source; throws std::logic_error in mode pid_1d.
  FollowerOutput on_targets(const wingman::targets_t& targets);
  /// A detections_t (mode pid_1d). Throws std::invalid_argument naming the field for a message before
  /// the previous one or an unknown source; throws std::logic_error in mode formation.
  FollowerOutput on_detections(const wingman::detections_t& detections);

  /// A heartbeat of the watched localizer (the caller subscribes to its status channel; mode formation
  /// only). Gives no setpoint: the next own pose or targets_t acts on it.
  void on_localizer_status(const wingman::status_t& status);

  const FollowerStatus& status() const { return status_; }
  ControllerMode mode() const { return mode_; }

 private:
  wingman::setpoint_t hold(int64_t utime, const std::string& reason);
  /// "" when the own pose is usable at `utime`, else why not.
  std::string own_pose_problem(int64_t utime) const;
  /// "" when the localizer watchdog lets the follower fly at message time `utime`, else why not.
  std::string localizer_problem(int64_t utime) const;
  /// Admits a message of `input` (the clock's id) at `utime`: throws std::invalid_argument with the problem when
  /// it is refused; on a resync forgets the time-keyed state and adds the note to `out`.
  void admit(int input, int64_t utime, FollowerOutput& out);
  /// Dates a heartbeat that came before any message time by the clock's first time.
  void saw_message_time();
  /// Forgets everything learnt from message times (a resync): as at start-up, but for the localizer's state.
  void forget_time_state();
  wingman::setpoint_t fly(int64_t utime, const VelocityCommand& command, int32_t track_id, int8_t source,
                          const std::string& what);

  FollowerOptions options_;
  ControllerMode mode_;
  int64_t timeout_us_;
  int64_t max_ahead_us_;  ///< time.max_ahead_s: the tolerance of cross-input ages
  common::StageClock clock_;
  int own_pose_input_;
  int driving_input_;
  SelectPolicy select_policy_;
  FormationController formation_;
  Pid1dController pid_1d_;
  std::optional<OwnState> own_;
  std::optional<int64_t> first_pose_utime_;
  double start_height_m_ = 0.0;
  std::optional<int64_t> last_driving_utime_;
  int8_t last_source_ = wingman::detections_t::SOURCE_CNN;
  int32_t followed_track_id_ = 0;           ///< formation: the track followed, 0 none
  std::optional<TargetState> last_target_;  ///< formation: the last usable state of the followed track
  int64_t followed_since_utime_ = 0;        ///< formation: newest image of the followed track when it was chosen
  std::optional<int64_t> last_box_utime_;   ///< pid_1d: utime of the last detections with a usable box
  int64_t localizer_timeout_us_;
  bool localizer_armed_ = false;                 ///< a localizer heartbeat has arrived
  std::optional<int64_t> localizer_seen_utime_;  ///< message time of the newest heartbeat (unset: none yet)
  int8_t localizer_state_ = wingman::status_t::STATE_STARTING;
  std::string localizer_detail_;
  FollowerStatus status_;
};

}  // namespace wingman::follower_ctrl
