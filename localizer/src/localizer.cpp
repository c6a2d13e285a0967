// SPDX-License-Identifier: MIT
// The localizer's logic: boxes -> camera-frame measurements -> world frame -> tracks -> targets_t.
#include "wingman/localizer/localizer.hpp"

#include "wingman/localizer/camera_to_world.hpp"

#include <fmt/format.h>
#include <wingman/common/detection_class.hpp>
#include <wingman/geometry/message_eigen.hpp>

#include <stdexcept>

namespace wingman::localizer {
std::string NonDroneCounts::summary() const {
  if (total == 0) return "";
  std::string by_class_text;
  for (const auto& [class_id, n] : by_class) {
    by_class_text +=
        fmt::format("{}{} {}", by_class_text.empty() ? "" : ", ", common::detection_class_name(class_id), n);
  }
  return fmt::format("non-drone boxes {}: {} ({})", tracked ? "tracked by their drone score" : "not tracked", total,
                     by_class_text);
}

Localizer::Localizer(const LocalizerOptions& options, geometry::CameraModel camera)
    : options_(options),
      cnn_relation_(BoxRelation::load(options.sphere.box_relation)),
      camera_(std::move(camera)),
      extrinsics_(geometry::Extrinsics::from_options(options.extrinsics)),
      poses_(options.pose),
      tracker_(options.tracker),
      clock_(options.time),
      own_pose_input_(clock_.add_input("own_pose_t.utime", "own pose", true)),
      detections_input_(clock_.add_input("detections_t.utime", "detections_t", true)) {}

void Localizer::on_own_pose(const wingman::own_pose_t& m) {
  PoseSample s;
  s.utime = m.utime;
  s.p_body_in_world = geometry::to_vector3(m.p_body_in_world);
  s.q_body_to_world = geometry::to_quaternion(m.q_body_to_world).normalized();
  s.v_body_in_world = geometry::to_vector3(m.v_body_in_world);
  if (m.has_covariance && options_.pose.use_covariance) {
    s.cov_p_body_in_world = geometry::from_upper_triangle(m.cov_p_body_in_world);
    s.var_rpy_body = geometry::to_vector3(m.var_rpy_body);
  }
  if (m.frame == wingman::own_pose_t::FRAME_NED) s = pose_ned_frd_to_enu_flu(s);  // world ENU, body FLU inside
  const common::TimeAdmission admission = clock_.admit(own_pose_input_, m.utime);
  if (!admission.accepted()) throw std::invalid_argument(admission.problem);
  if (admission.resynced()) {  // the buffered poses belong to the old times: forget them
    poses_ = PoseBuffer(options_.pose);
    newest_pose_utime_ = -1;
    notes_.push_back(admission.problem + "; the own-pose buffer is emptied");
  }
  std::string why;
  if (!poses_.add(s, &why)) throw std::invalid_argument("own_pose_t.utime = " + std::to_string(m.utime) + ": " + why);
  newest_pose_utime_ = std::max(newest_pose_utime_, m.utime);
}

LocalizerOutput Localizer::on_detections(const wingman::detections_t& d) {
  if (d.camera_id != options_.camera.camera_id) {
    throw std::invalid_argument(fmt::format("detections_t.camera_id = {}: this localizer takes camera {}", d.camera_id,
                                            options_.camera.camera_id));
  }
  if (d.image_width != camera_.width() || d.image_height != camera_.height()) {
    if (!options_.camera.scale_to_image) {
      throw std::invalid_argument("detections_t.image_width x image_height: " +
                                  camera_.check_image_size(d.image_width, d.image_height));
    }
    camera_ = camera_.scaled_to(d.image_width, d.image_height);
  }
  const bool ground_truth = d.source == wingman::detections_t::SOURCE_GROUND_TRUTH;
  if (!ground_truth) {
    if (const std::string bad = cnn_relation_.check_model(d.model_id); !bad.empty()) throw std::invalid_argument(bad);
  }
  const common::TimeAdmission admission = clock_.admit(detections_input_, d.utime);
  if (!admission.accepted()) throw std::invalid_argument(admission.problem);
  if (admission.resynced()) {  // its tracks live in the old times
    tracker_ = Tracker(options_.tracker);
    previous_detections_utime_ = -1;
    notes_.push_back(admission.problem + "; the tracker restarts (new track ids)");
  }

  LocalizerOutput result;
  std::vector<CameraMeasurement> measurements;
  const bool track_every_class = options_.class_decision == "track";
  result.non_drone.tracked = track_every_class;
  for (size_t i = 0; i < d.detections.size(); ++i) {
    const auto& det = d.detections[i];
    if (det.class_id != common::kDroneClassId) {  // a distractor class of a multi-class model
      ++result.non_drone.total;
      ++result.non_drone.by_class[det.class_id];
      if (!track_every_class) continue;  // decided per box: never a target
    }
    const geometry::PixelBox box{det.cx, det.cy, det.w, det.h};
    const BoxScale scale = ground_truth ? BoxScale{} : cnn_relation_.at(det.w, det.h, d.image_width);
    LocalizeResult r = localize_box(box, camera_, options_.sphere, scale);
    if (!r.ok) {
      result.rejections.push_back(fmt::format("detections_t.detections[{}]: {}", i, r.reason));
      continue;
    }
    // Decided per track: the tracker's evidence is the box's drone score (the same as its confidence for a drone box).
    r.measurement.confidence = track_every_class ? det.drone_score : det.confidence;
    measurements.push_back(r.measurement);
  }
  non_drone_boxes_.tracked = track_every_class;
  non_drone_boxes_.total += result.non_drone.total;
  for (const auto& [class_id, n] : result.non_drone.by_class) non_drone_boxes_.by_class[class_id] += n;

  std::string why;
  const std::optional<PoseSample> pose = poses_.at(d.utime, &why);
  if (!pose) {
    result.camera_frame_only = true;
    result.rejections.push_back("no own pose at detections_t.utime = " + std::to_string(d.utime) + ": " + why);
    if (options_.publish_camera_frame_only) result.targets = camera_frame_targets(d, measurements);
    return result;
  }

  std::vector<WorldMeasurement> world;
  world.reserve(measurements.size());
  for (const auto& m : measurements) {
    if (!m.range_valid) continue;  // bearing-only: not a position; the tracker takes positions
    world.push_back(to_world(m, extrinsics_, *pose, d.utime, d.camera_id));
  }
  if (!tracker_.update(d.utime, world, &why)) {
    throw std::invalid_argument("detections_t.utime = " + std::to_string(d.utime) + ": " + why);
  }
  if (options_.windows.publish) result.windows = track_windows(d, *pose);
  previous_detections_utime_ = d.utime;

  // Lag compensation: predict to the newest time we know of (own poses arrive with little delay).
  const int64_t predict_to = std::max(d.utime, newest_pose_utime_);
  wingman::targets_t out{};
  out.utime = predict_to;
  out.frame = wingman::own_pose_t::FRAME_ENU;
  for (const TrackOutput& t : tracker_.confirmed(predict_to)) {
    wingman::target_t m{};
    m.track_id = t.track_id;
    m.camera_id = t.camera_id;
    geometry::to_array(t.p_target_in_cam, m.p_target_in_cam);
    geometry::to_array(t.p_target_in_world, m.p_target_in_world);
    geometry::to_array(t.v_target_in_world, m.v_target_in_world);
    geometry::to_array(t.cov_p, m.position_covariance);
    geometry::to_array(t.cov_v, m.velocity_covariance);
    m.world_valid = true;
    m.range = t.range;
    m.radius_m = t.size_scale * options_.sphere.radius_m;
    m.radius_sigma_m = t.size_scale_sigma * options_.sphere.radius_m;
    m.confidence = static_cast<float>(t.confidence);
    m.age_s = static_cast<float>(t.age_s);
    m.source_utime = t.source_utime;
    m.predicted_utime = t.predicted_utime;
    m.detection_source = d.source;
    out.targets.push_back(m);
  }
  out.num_targets = static_cast<int32_t>(out.targets.size());
  if (out.num_targets > 0 || options_.publish_empty) result.targets = std::move(out);
  return result;
}

wingman::track_windows_t Localizer::track_windows(const wingman::detections_t& d, const PoseSample& pose) const {
  // The next exposure: one frame interval (the last one seen, at most 0.5 s) after this one.
  constexpr int64_t kMaxInterval_us = 500000;
  const int64_t interval_us = previous_detections_utime_ >= 0 && d.utime - previous_detections_utime_ <= kMaxInterval_us
                                  ? d.utime - previous_detections_utime_
                                  : 0;
  wingman::track_windows_t out{};
  out.utime = d.utime;
  out.utime_predicted = d.utime + interval_us;
  out.camera_id = d.camera_id;
  out.image_width = d.image_width;
  out.image_height = d.image_height;
  // The camera then: the pose at this exposure moved on with the body's velocity (its rotation held).
  const double dt = static_cast<double>(interval_us) * 1e-6;
  const CameraPoseInWorld now = camera_pose_in_world(extrinsics_, pose);
  CameraAtExposure cam;
  cam.R_cam_to_world = now.R_cam_to_world;
  cam.v_cam_in_world = pose.v_body_in_world;
  cam.p_cam_in_world = now.p_cam_in_world + dt * pose.v_body_in_world;
  const bool ground_truth = d.source == wingman::detections_t::SOURCE_GROUND_TRUTH;
  static const BoxRelation sphere = BoxRelation::sphere();  // built once, not per frame
  for (const TrackOutput& t : tracker_.predicted_tracks(out.utime_predicted)) {
    if (static_cast<int>(out.windows.size()) >= options_.windows.max_windows) break;
    // The box relation holds for full-resolution re-detections too (measured: docs/detector.md, "Tracker-driven
    // windows").
    if (auto w = predict_track_window(t, options_.sphere.radius_m, camera_, cam, ground_truth ? sphere : cnn_relation_))
      out.windows.push_back(*w);
  }
  out.num_windows = static_cast<int32_t>(out.windows.size());
  return out;
}

wingman::targets_t Localizer::camera_frame_targets(const wingman::detections_t& d,
                                                   const std::vector<CameraMeasurement>& measurements) const {
  wingman::targets_t out{};
  out.utime = d.utime;
  out.frame = wingman::own_pose_t::FRAME_ENU;
  for (const auto& m : measurements) {
    wingman::target_t t{};
    t.track_id = 0;  // untracked: tracks live in the world frame
    t.camera_id = d.camera_id;
    geometry::to_array(m.p_target_in_cam, t.p_target_in_cam);
    geometry::to_array(m.cov_p_in_cam, t.position_covariance);
    t.world_valid = false;
    t.range = m.range_valid ? m.range : 0.0;
    t.confidence = static_cast<float>(m.confidence);
    t.source_utime = d.utime;
    t.predicted_utime = d.utime;
    t.detection_source = d.source;
    out.targets.push_back(t);
  }
  out.num_targets = static_cast<int32_t>(out.targets.size());
  return out;
}

std::string Localizer::tracker_summary() const {
  const size_t held = tracker_.num_held();
  if (held == 0) return "";
  return fmt::format(
      "{} tentative track(s) with {} hits held back: mean confidence of the last {} below "
      "tracker.confirm_min_confidence {}",
      held, options_.tracker.birth_hits, options_.tracker.birth_window, options_.tracker.confirm_min_confidence);
}

std::vector<std::string> Localizer::take_notes() {
  std::vector<std::string> out;
  out.swap(notes_);
  return out;
}

}  // namespace wingman::localizer
