// SPDX-License-Identifier: MIT
// The localizer's logic: boxes -> camera-frame measurements -> world frame -> tracks -> targets_t.
#include "wingman/localizer/localizer.hpp"

#include "wingman/localizer/camera_to_world.hpp"

#include <fmt/format.h>
#include <wingman/common/detection_class.hpp>
#include <wingman/geometry/calibration.hpp>
#include <wingman/geometry/message_eigen.hpp>

#include <algorithm>
#include <functional>
#include <stdexcept>

namespace wingman::localizer {

static_assert(BoxRelation::kPassSingle == wingman::detection_t::PASS_SINGLE &&
                  BoxRelation::kPassWindow == wingman::detection_t::PASS_WINDOW,
              "BoxRelation's pass constants are detection_t's");
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
      poses_(options.pose),
      tracker_(options.tracker),
      clock_(options.time),
      own_pose_input_(clock_.add_input("own_pose_t.utime", "own pose", true)) {
  cameras_.emplace_back(options.camera.camera_id, std::move(camera),
                        geometry::Extrinsics::from_options(options.extrinsics), options.detections_channel,
                        options.windows.channel);
  camera_inputs_.push_back(clock_.add_input("detections_t.utime", "detections_t", true));
}

Localizer::Localizer(const LocalizerOptions& options, const geometry::CameraRig& rig)
    : options_(options),
      rig_(true),
      cnn_relation_(BoxRelation::load(options.sphere.box_relation)),
      poses_(options.pose),
      tracker_(options.tracker),
      clock_(options.time),
      own_pose_input_(clock_.add_input("own_pose_t.utime", "own pose", true)) {
  if (rig.cameras.empty()) throw std::invalid_argument("cameras.rig = '" + rig.source + "': no cameras");
  CameraRigOptions keys = options.cameras;
  keys.rig.clear();  // read already: `rig`
  if (const std::vector<std::string> bad = keys.validate(); !bad.empty()) {
    std::string all = "invalid cameras.*:";
    for (const std::string& b : bad) all += " " + b + ";";
    throw std::invalid_argument(all);
  }
  for (const geometry::RigCamera& c : rig.cameras) {
    cameras_.emplace_back(c.camera.camera_id, geometry::make_camera(c.camera),
                          geometry::Extrinsics::from_options(c.extrinsics), c.detections_channel, c.windows_channel);
    camera_inputs_.push_back(
        clock_.add_input("detections_t.utime", fmt::format("camera {} detections_t", c.camera.camera_id), true));
  }
}

Localizer Localizer::from_options(const LocalizerOptions& options) {
  if (options.cameras.rig.empty()) return Localizer(options, geometry::make_camera(options.camera));
  return Localizer(options, geometry::load_camera_rig(options.cameras.rig));
}

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

void Localizer::admit(LocalizerCamera& c, int clock_input, const wingman::detections_t& d) {
  if (d.image_width != c.camera.width() || d.image_height != c.camera.height()) {
    if (!options_.camera.scale_to_image) {
      throw std::invalid_argument("detections_t.image_width x image_height: " +
                                  c.camera.check_image_size(d.image_width, d.image_height));
    }
    c.camera = c.camera.scaled_to(d.image_width, d.image_height);
  }
  const bool ground_truth = d.source == wingman::detections_t::SOURCE_GROUND_TRUTH;
  if (!ground_truth) {
    if (const std::string bad = cnn_relation_.check_model(d.model_id); !bad.empty()) throw std::invalid_argument(bad);
  }
  // A resync of another input (the own pose) makes the clock forget this camera when its times lie far after it: time
  // went back for everyone (a restarted source). The tracks (and a rig's waiting exposures) of the old times go, as
  // after a resync of this input; otherwise the tracker would refuse every frame as not after its last one.
  const bool forgotten = c.last_utime >= 0 && !clock_.previous(clock_input).has_value();
  const common::TimeAdmission admission = clock_.admit(clock_input, d.utime);
  if (!admission.accepted()) throw std::invalid_argument(admission.problem);
  const char* const restarts = rig_ ? "the tracker restarts (new track ids), the waiting exposures are dropped"
                                    : "the tracker restarts (new track ids)";
  if (admission.resynced()) {
    restart(nullptr);  // its tracks live in the old times; so do the waiting exposures and what each camera sent
    notes_.push_back(admission.problem + "; " + restarts);
  } else if (forgotten && d.utime <= std::max(c.last_utime, processed_utime_)) {
    restart(&c);
    notes_.push_back(fmt::format("detections_t.utime = {}: {}time went back with a resync of another input; {}",
                                 d.utime, rig_ ? fmt::format("camera {}'s ", d.camera_id) : std::string(), restarts));
  }
  ++c.messages;
  c.last_utime = d.utime;
}

LocalizerOutput Localizer::on_detections(const wingman::detections_t& d) {
  if (rig_) throw std::logic_error("Localizer::on_detections: a camera rig takes add_detections()");
  if (d.camera_id != cameras_[0].camera_id) {
    throw std::invalid_argument(fmt::format("detections_t.camera_id = {}: this localizer takes camera {}", d.camera_id,
                                            options_.camera.camera_id));
  }
  admit(cameras_[0], camera_inputs_[0], d);
  return process(d.utime, {&d});
}

std::vector<LocalizerOutput> Localizer::add_detections(const wingman::detections_t& d) {
  if (!rig_) return {on_detections(d)};
  size_t i = 0;
  while (i < cameras_.size() && cameras_[i].camera_id != d.camera_id) ++i;
  if (i == cameras_.size()) {
    std::string ids;
    for (const LocalizerCamera& c : cameras_) ids += fmt::format("{}{}", ids.empty() ? "" : ", ", c.camera_id);
    throw std::invalid_argument(fmt::format("detections_t.camera_id = {}: not a camera of the rig {} (cameras.rig: {})",
                                            d.camera_id, options_.cameras.rig, ids));
  }
  admit(cameras_[i], camera_inputs_[i], d);
  if (first_utime_ < 0) first_utime_ = d.utime;
  if (d.utime <= processed_utime_) {  // a sign of life all the same (admit() counted it)
    ++exposure_stats_.late;
    throw std::invalid_argument(
        fmt::format("detections_t.utime = {}: camera {} is late: the exposures up to {} were processed without it",
                    d.utime, d.camera_id, processed_utime_));
  }
  auto [it, added] = pending_.try_emplace(d.utime);
  if (added) it->second.resize(cameras_.size());
  it->second[i] = d;

  std::vector<LocalizerOutput> out;
  while (!pending_.empty()) {
    const auto oldest = pending_.begin();
    const int64_t utime = oldest->first;
    // Ready when no camera it lacks is still to be waited for: such a camera sent a later exposure (it will not send
    // this one), is silent, or is overtaken (every other camera that is not silent has sent a later exposure).
    bool ready = true, missing = false;
    for (size_t c = 0; c < cameras_.size() && ready; ++c) {
      if (oldest->second[c]) continue;
      missing = true;
      if (cameras_[c].last_utime > utime || silent(c)) continue;
      for (size_t o = 0; o < cameras_.size(); ++o)
        if (o != c && cameras_[o].last_utime <= utime && !silent(o)) ready = false;
    }
    const bool overflow = static_cast<int>(pending_.size()) > options_.cameras.max_pending;
    if (!ready && !overflow) break;
    const std::vector<std::optional<wingman::detections_t>> messages = std::move(oldest->second);
    pending_.erase(oldest);  // gone whatever process() does
    std::vector<const wingman::detections_t*> per_camera(cameras_.size(), nullptr);
    for (size_t c = 0; c < cameras_.size(); ++c)
      if (messages[c]) per_camera[c] = &*messages[c];
    ++exposure_stats_.processed;
    if (missing) ++exposure_stats_.incomplete;
    if (!ready) ++exposure_stats_.overflowed;
    processed_utime_ = utime;
    out.push_back(process(utime, per_camera));
  }
  return out;
}

void Localizer::restart(const LocalizerCamera* keep) {
  tracker_ = Tracker(options_.tracker);
  pending_.clear();
  processed_utime_ = -1;
  first_utime_ = -1;
  for (LocalizerCamera& c : cameras_) {
    c.processed_utime = -1;
    if (&c != keep) c.last_utime = -1;
  }
}

int64_t Localizer::newest_camera_utime() const {
  int64_t newest = first_utime_;
  for (const LocalizerCamera& c : cameras_) newest = std::max(newest, c.last_utime);
  return newest;
}

bool Localizer::silent(size_t i) const {
  if (first_utime_ < 0) return false;
  const int64_t newest = newest_camera_utime();
  const int64_t since = cameras_[i].last_utime >= 0 ? cameras_[i].last_utime : first_utime_;
  return static_cast<double>(newest - since) > options_.cameras.silent_after_s * 1e6;
}

std::string Localizer::silent_summary() const {
  if (!rig_ || first_utime_ < 0) return "";
  const int64_t newest = newest_camera_utime();
  std::string out;
  for (size_t i = 0; i < cameras_.size(); ++i) {
    if (!silent(i)) continue;
    const LocalizerCamera& c = cameras_[i];
    const int64_t since = c.last_utime >= 0 ? c.last_utime : first_utime_;
    out += fmt::format("{}camera {} silent for {:.1f} s{}", out.empty() ? "" : ", ", c.camera_id,
                       static_cast<double>(newest - since) * 1e-6, c.last_utime >= 0 ? "" : " (no message yet)");
  }
  return out;
}

std::string Localizer::cameras_summary() const {
  if (!rig_) return "";
  std::string out = "detections_t per camera:";
  for (size_t i = 0; i < cameras_.size(); ++i)
    out += fmt::format("{} {} {}", i == 0 ? "" : ",", cameras_[i].camera_id, cameras_[i].messages);
  if (exposure_stats_.incomplete > 0)
    out += fmt::format(" ({} of {} exposures without every camera)", exposure_stats_.incomplete,
                       exposure_stats_.processed);
  return out;
}

namespace {

/// Ratio 1: ground-truth detections are the sphere's boxes (built once, not per frame).
const BoxRelation& sphere_relation() {
  static const BoxRelation sphere = BoxRelation::sphere();
  return sphere;
}

/// The camera-frame targets of `measurements` (no own pose: untracked), of camera `d.camera_id`, appended to `out`.
void append_camera_frame_targets(const wingman::detections_t& d, const std::vector<CameraMeasurement>& measurements,
                                 wingman::targets_t& out) {
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
}

}  // namespace

LocalizerOutput Localizer::process(int64_t utime, const std::vector<const wingman::detections_t*>& per_camera) {
  LocalizerOutput result;
  result.utime = utime;
  const bool track_every_class = options_.class_decision == "track";
  result.non_drone.tracked = track_every_class;
  const wingman::detections_t* first = nullptr;  // the first camera's message that is there
  std::vector<std::vector<CameraMeasurement>> measurements(per_camera.size());
  for (size_t c = 0; c < per_camera.size(); ++c) {
    const wingman::detections_t* d = per_camera[c];
    if (d == nullptr) continue;
    if (first == nullptr) first = d;
    const bool ground_truth = d->source == wingman::detections_t::SOURCE_GROUND_TRUTH;
    for (size_t i = 0; i < d->detections.size(); ++i) {
      const auto& det = d->detections[i];
      if (det.class_id != common::kDroneClassId) {  // a distractor class of a multi-class model
        ++result.non_drone.total;
        ++result.non_drone.by_class[det.class_id];
        if (!track_every_class) continue;  // decided per box: never a target
      }
      const geometry::PixelBox box{det.cx, det.cy, det.w, det.h};
      const BoxScale scale = ground_truth ? BoxScale{} : cnn_relation_.at(det.w, det.h, d->image_width, det.pass_kind);
      LocalizeResult r = localize_box(box, cameras_[c].camera, options_.sphere, scale);
      if (!r.ok) {
        result.rejections.push_back(
            rig_ ? fmt::format("camera {}: detections_t.detections[{}]: {}", d->camera_id, i, r.reason)
                 : fmt::format("detections_t.detections[{}]: {}", i, r.reason));
        result.rejection_channels.push_back(cameras_[c].detections_channel);
        continue;
      }
      // Decided per track: the tracker's evidence is the box's drone score (the same as its confidence for a drone
      // box).
      r.measurement.confidence = track_every_class ? det.drone_score : det.confidence;
      measurements[c].push_back(r.measurement);
    }
  }
  non_drone_boxes_.tracked = track_every_class;
  non_drone_boxes_.total += result.non_drone.total;
  for (const auto& [class_id, n] : result.non_drone.by_class) non_drone_boxes_.by_class[class_id] += n;

  std::string why;
  const std::optional<PoseSample> pose = poses_.at(utime, &why);
  if (!pose) {
    result.camera_frame_only = true;
    result.rejections.push_back("no own pose at detections_t.utime = " + std::to_string(utime) + ": " + why);
    for (size_t c = 0; c < per_camera.size(); ++c)
      if (per_camera[c] != nullptr) {
        result.rejection_channels.push_back(cameras_[c].detections_channel);
        break;
      }
    if (options_.publish_camera_frame_only) {
      wingman::targets_t out{};
      out.utime = utime;
      out.frame = wingman::own_pose_t::FRAME_ENU;
      for (size_t c = 0; c < per_camera.size(); ++c)
        if (per_camera[c] != nullptr) append_camera_frame_targets(*per_camera[c], measurements[c], out);
      out.num_targets = static_cast<int32_t>(out.targets.size());
      result.targets = std::move(out);
    }
    return result;
  }

  std::vector<std::vector<WorldMeasurement>> world(per_camera.size());
  for (size_t c = 0; c < per_camera.size(); ++c) {
    world[c].reserve(measurements[c].size());
    for (const auto& m : measurements[c]) {
      if (!m.range_valid) continue;  // bearing-only: not a position; the tracker takes positions
      world[c].push_back(to_world(m, cameras_[c].extrinsics, *pose, utime, per_camera[c]->camera_id));
    }
  }
  // A rig: a track none of this exposure's cameras could see is not missed by it (cameras not triggered together make
  // every exposure one camera's; a track in another camera's view would otherwise miss three frames of four).
  // Each camera of the exposure in the world at its time, once (the view test, the occlusion rule and the windows).
  std::vector<CameraPoseInWorld> cam_in_world(per_camera.size());
  for (size_t c = 0; c < per_camera.size(); ++c)
    if (per_camera[c] != nullptr) cam_in_world[c] = camera_pose_in_world(cameras_[c].extrinsics, *pose);
  FrameViews views;
  if (rig_) {
    views.could_see = [&](const Eigen::Vector3d& p_target_in_world) {
      for (size_t c = 0; c < per_camera.size(); ++c) {
        if (per_camera[c] == nullptr) continue;
        const CameraPoseInWorld& cam = cam_in_world[c];
        const Eigen::Vector3d p_in_cam = cam.R_cam_to_world.transpose() * (p_target_in_world - cam.p_cam_in_world);
        if (!(p_in_cam.z() > 1e-3 * p_in_cam.norm())) continue;  // behind the camera or beside it
        const Eigen::Vector2d uv = cameras_[c].camera.project(p_in_cam);
        if (uv.x() >= 0 && uv.y() >= 0 && uv.x() <= cameras_[c].camera.width() && uv.y() <= cameras_[c].camera.height())
          return true;
      }
      return false;
    };
  }
  if (options_.tracker.occlusion_coast) views.occluded = occluded_tracks(utime, per_camera, cam_in_world);
  if (!tracker_.update_cameras(utime, world, &why, views)) {
    throw std::invalid_argument("detections_t.utime = " + std::to_string(utime) + ": " + why);
  }
  // Windows for the cameras of this exposure, each for its own next exposure.
  for (size_t c = 0; c < per_camera.size(); ++c) {
    if (per_camera[c] == nullptr) continue;
    if (options_.windows.publish) {
      wingman::track_windows_t w = track_windows(utime, cameras_[c], first->source, *pose, cam_in_world[c]);
      if (rig_) {
        result.camera_windows.push_back({cameras_[c].windows_channel, std::move(w)});
      } else {
        result.windows = std::move(w);
      }
    }
    cameras_[c].processed_utime = utime;
  }

  // Lag compensation: predict to the newest time we know of (own poses arrive with little delay).
  const int64_t predict_to = std::max(utime, newest_pose_utime_);
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
    m.detection_source = first->source;
    out.targets.push_back(m);
  }
  out.num_targets = static_cast<int32_t>(out.targets.size());
  if (out.num_targets > 0 || options_.publish_empty) result.targets = std::move(out);
  return result;
}

std::vector<std::vector<int32_t>> Localizer::occluded_tracks(
    int64_t utime, const std::vector<const wingman::detections_t*>& per_camera,
    const std::vector<CameraPoseInWorld>& cam_in_world) const {
  std::vector<std::vector<int32_t>> out(per_camera.size());
  if (tracker_.num_confirmed() < 2) return out;
  std::vector<TrackOutput> tracks = tracker_.predicted_tracks(utime);
  tracks.erase(std::remove_if(tracks.begin(), tracks.end(), [](const TrackOutput& t) { return !t.confirmed; }),
               tracks.end());
  const double m = options_.tracker.occlusion_margin;
  for (size_t c = 0; c < per_camera.size(); ++c) {
    if (per_camera[c] == nullptr) continue;
    const bool ground_truth = per_camera[c]->source == wingman::detections_t::SOURCE_GROUND_TRUTH;
    CameraAtExposure cam;
    cam.R_cam_to_world = cam_in_world[c].R_cam_to_world;
    cam.p_cam_in_world = cam_in_world[c].p_cam_in_world;
    // Each track's predicted box, grown by the margin on every side: left, top, right, bottom.
    std::vector<std::pair<int32_t, Eigen::Vector4d>> boxes;
    for (const TrackOutput& t : tracks) {
      const auto w = predict_track_window(t, options_.sphere.radius_m, cameras_[c].camera, cam,
                                          ground_truth ? sphere_relation() : cnn_relation_);
      if (!w) continue;
      const double hw = (0.5 + m) * w->w, hh = (0.5 + m) * w->h;
      boxes.push_back({t.track_id, Eigen::Vector4d(w->cx - hw, w->cy - hh, w->cx + hw, w->cy + hh)});
    }
    for (size_t a = 0; a < boxes.size(); ++a)
      for (size_t b = a + 1; b < boxes.size(); ++b) {
        const Eigen::Vector4d& p = boxes[a].second;
        const Eigen::Vector4d& q = boxes[b].second;
        if (p[0] >= q[2] || q[0] >= p[2] || p[1] >= q[3] || q[1] >= p[3]) continue;  // apart
        // One drone followed twice (their states agree: the merge rule will join them) is no occlusion: coasting would
        // only leave the drone's track without updates until the merge.
        if (tracker_.agree(boxes[a].first, boxes[b].first)) continue;
        for (const int32_t id : {boxes[a].first, boxes[b].first})
          if (std::find(out[c].begin(), out[c].end(), id) == out[c].end()) out[c].push_back(id);
      }
  }
  return out;
}

wingman::track_windows_t Localizer::track_windows(int64_t utime, const LocalizerCamera& c, int8_t source,
                                                  const PoseSample& pose, const CameraPoseInWorld& now) const {
  // The camera's next exposure: one of its frame intervals (the last one seen, at most 0.5 s) after this one.
  constexpr int64_t kMaxInterval_us = 500000;
  const int64_t interval_us =
      c.processed_utime >= 0 && utime - c.processed_utime <= kMaxInterval_us ? utime - c.processed_utime : 0;
  wingman::track_windows_t out{};
  out.utime = utime;
  out.utime_predicted = utime + interval_us;
  out.camera_id = c.camera_id;
  out.image_width = c.camera.width();
  out.image_height = c.camera.height();
  // The camera then: the pose at this exposure moved on with the body's velocity (its rotation held).
  const double dt = static_cast<double>(interval_us) * 1e-6;
  CameraAtExposure cam;
  cam.R_cam_to_world = now.R_cam_to_world;
  cam.v_cam_in_world = pose.v_body_in_world;
  cam.p_cam_in_world = now.p_cam_in_world + dt * pose.v_body_in_world;
  const bool ground_truth = source == wingman::detections_t::SOURCE_GROUND_TRUTH;
  for (const TrackOutput& t : tracker_.predicted_tracks(out.utime_predicted)) {
    if (static_cast<int>(out.windows.size()) >= options_.windows.max_windows) break;
    // The single pass's box (the main grid): it decides whether the detector searches a window (by its size in the
    // single pass's network pixels). A window's own box of a far drone is up to a fifth wider (the window grid), which
    // would widen the gate by a pixel or two.
    if (auto w = predict_track_window(t, options_.sphere.radius_m, c.camera, cam,
                                      ground_truth ? sphere_relation() : cnn_relation_))
      out.windows.push_back(*w);
  }
  out.num_windows = static_cast<int32_t>(out.windows.size());
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
