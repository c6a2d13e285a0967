// SPDX-License-Identifier: MIT
// Track-level metrics: clips -> detector -> wingman-localizer's Localizer -> confirmed tracks -> false tracks per hour,
// drone clips confirmed and time to confirm.
#include "wingman/training/sequence_eval.hpp"

#include "wingman/training/halmstad_labels.hpp"

#include "wingman/training/yolo_dataset.hpp"

#include <wingman/common/config.hpp>
#include <wingman/common/detection_class.hpp>
#include <wingman/common/json.hpp>
#include <wingman/detector/detection_message.hpp>
#include <wingman/detector/input_size.hpp>
#include <wingman/detector/model_loader.hpp>
#include <wingman/detector/sized_detector.hpp>
#include <wingman/detector/track_windows.hpp>
#include <wingman/geometry/message_eigen.hpp>
#include <wingman/localizer/sphere_localizer.hpp>

#include <fmt/format.h>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace wingman::training {

namespace fs = std::filesystem;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// The classes a Halmstad label may name; DRONE is the tracked one.
const std::vector<std::string>& kHalmstadClasses = halmstad_label_classes();
/// Distance bins in the order the report lists them.
const std::vector<std::string> kDistanceBins = {"CLOSE", "MEDIUM", "DISTANT"};

bool blank(const std::string& line) { return line.empty() || line == "\r"; }

/// Centre in box, inclusive, as `wingman val`'s centre criterion (detection_metrics.cpp).
bool centre_inside(double cx, double cy, const cv::Rect2d& t) {
  return cx >= t.x && cx <= t.x + t.width && cy >= t.y && cy <= t.y + t.height;
}

double median(std::vector<double> v) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 == 1 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

/// P(X <= k) for X ~ Poisson(lambda).
double poisson_cdf(int k, double lambda) {
  if (lambda <= 0) return 1.0;
  double sum = 0;
  for (int i = 0; i <= k; ++i) sum += std::exp(-lambda + i * std::log(lambda) - std::lgamma(i + 1.0));
  return std::min(1.0, sum);
}

/// The exact one-sided 95 % upper confidence bound of a Poisson mean after observing k events: the lambda with
/// P(X <= k; lambda) = 0.05 (k = 0: -ln 0.05 = 3.00).
double poisson_upper95(int k) {
  double lo = 0, hi = 10.0 + 3.0 * k;
  while (poisson_cdf(k, hi) > 0.05) hi *= 2;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (poisson_cdf(k, mid) > 0.05 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

struct SplitClip {
  std::string name, cls, distance_bin;
};

/// The clips of `split` in `path` (splits.csv: clip,class,distance_bin,split,images), by name.
std::vector<SplitClip> read_splits(const std::string& path, const std::string& split) {
  if (!fs::is_regular_file(path))
    throw DatasetError(
        fmt::format("{}: no splits.csv: give the folder `wingman import-halmstad` wrote (or its "
                    "data.yaml)",
                    path));
  std::ifstream in(path);
  if (!in) throw DatasetError(fmt::format("{}: cannot read the split list", path));
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split_csv_line(line);
  if (header.size() < 4 || header[0] != "clip" || header[1] != "class" || header[2] != "distance_bin" ||
      header[3] != "split")
    throw DatasetError(
        fmt::format("{}:1: expected the header 'clip,class,distance_bin,split,images', got '{}'", path, line));
  std::vector<SplitClip> clips;
  std::set<std::string> seen;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (blank(line)) continue;
    const std::vector<std::string> f = split_csv_line(line);
    if (f.size() < 4)
      throw DatasetError(fmt::format("{}:{}: expected at least 4 fields, got {}", path, line_no, f.size()));
    if (f[0].empty()) throw DatasetError(fmt::format("{}:{}: empty clip name", path, line_no));
    if (std::find(kHalmstadClasses.begin(), kHalmstadClasses.end(), f[1]) == kHalmstadClasses.end())
      throw DatasetError(
          fmt::format("{}:{}: field class = '{}': expected DRONE, AIRPLANE, BIRD or HELICOPTER", path, line_no, f[1]));
    if (!seen.insert(f[0]).second)
      throw DatasetError(fmt::format("{}:{}: clip '{}' listed twice", path, line_no, f[0]));
    if (f[3] == split) clips.push_back({f[0], f[1], f[2]});
  }
  std::sort(clips.begin(), clips.end(), [](const SplitClip& a, const SplitClip& b) { return a.name < b.name; });
  return clips;
}

/// A time that may be missing (negative: never happened) as JSON: null when missing or not finite.
common::Json seconds_or_null(double v) { return v < 0 || !std::isfinite(v) ? common::Json(nullptr) : common::Json(v); }

}  // namespace

// ---------------------------------------------------------------------------------------------------------------------
// Options

std::vector<std::string> TrackScoringOptions::validate() const {
  std::vector<std::string> p;
  if (!(on_target_fraction >= 0.0 && on_target_fraction < 1.0))
    p.push_back(fmt::format("scoring.on_target_fraction = {}: must be in [0, 1)", on_target_fraction));
  if (!(confirm_within_s > 0.0) || !std::isfinite(confirm_within_s))
    p.push_back(fmt::format("scoring.confirm_within_s = {}: must be > 0 (seconds)", confirm_within_s));
  return p;
}

std::vector<std::string> SequenceEvalOptions::validate() const {
  std::vector<std::string> p;
  if (data.empty()) p.push_back("data is empty: the folder `wingman import-halmstad` wrote (splits.csv) is required");
  if (halmstad_root.empty()) p.push_back("halmstad_root is empty: the Halmstad dataset folder is required");
  if (split.empty()) p.push_back("split is empty");
  if (weights.empty()) p.push_back("weights is empty: a .weights path or builtin:wingman-small");
  if (backend != "auto" && backend != "opencl" && backend != "cpu")
    p.push_back(fmt::format("backend = '{}': must be auto, opencl or cpu", backend));
  if (std::string why; !detector::InputSize::parse(input_size, &why)) p.push_back("input_size = " + why);
  if (!(hfov_deg > 0.0 && hfov_deg < 180.0)) p.push_back(fmt::format("hfov_deg = {}: must be in (0, 180)", hfov_deg));
  if (frame_step < 1) p.push_back(fmt::format("frame_step = {}: must be >= 1", frame_step));
  if (!(max_seconds >= 0.0) || !std::isfinite(max_seconds))
    p.push_back(fmt::format("max_seconds = {}: must be >= 0 (0: whole clips)", max_seconds));
  for (const auto& s : detection.validate()) p.push_back(s);
  for (const auto& s : scoring.validate()) p.push_back(s);
  if (motion.enabled) {
    for (const auto& s : motion.validate()) p.push_back(s);
    for (const auto& s : windows.validate()) p.push_back(s);
  }
  return p;
}

geometry::CameraModel nominal_pinhole(int width, int height, double hfov_deg) {
  if (width < 1 || height < 1)
    throw std::invalid_argument(fmt::format("nominal_pinhole: image size {}x{}: must be positive", width, height));
  if (!(hfov_deg > 0.0 && hfov_deg < 180.0))
    throw std::invalid_argument(fmt::format("nominal_pinhole: hfov_deg = {}: must be in (0, 180)", hfov_deg));
  const double f = 0.5 * width / std::tan(0.5 * hfov_deg * kPi / 180.0);
  // Principal point at the image centre in the calibration convention (pixel centres at integers), as
  // wingman-localizer's built-in pinhole.
  return geometry::CameraModel::pinhole(width, height, f, f, 0.5 * width - 0.5, 0.5 * height - 0.5,
                                        fmt::format("nominal pinhole {}x{}, HFOV {} deg", width, height, hfov_deg));
}

// ---------------------------------------------------------------------------------------------------------------------
// ClipTracker

ClipTracker::ClipTracker(const localizer::LocalizerOptions& options, geometry::CameraModel camera, double fps)
    : options_(options), camera_(std::move(camera)), fps_(fps) {
  if (!(fps > 0.0) || !std::isfinite(fps))
    throw std::invalid_argument(fmt::format("ClipTracker: fps = {}: must be > 0", fps));
  options_.camera.scale_to_image = false;  // the camera is the frames' own
  localizer_ = std::make_unique<localizer::Localizer>(options_, camera_);
  relation_ = localizer::BoxRelation::load(options_.sphere.box_relation);
}

ClipTracker::~ClipTracker() = default;

void ClipTracker::add_frame(int frame_index, const std::vector<detector::Box>& boxes,
                            const std::vector<cv::Rect2d>& drone_truths) {
  if (frame_index <= last_frame_)
    throw std::invalid_argument(fmt::format(
        "ClipTracker: frame {} after frame {}: frames must come in increasing order", frame_index, last_frame_));
  last_frame_ = frame_index;
  ++frames_;
  const int64_t utime = kClipStartUtime + std::llround(static_cast<double>(frame_index) * 1e6 / fps_);

  // The camera stands still: body at the world origin, unrotated, at this frame's time.
  wingman::own_pose_t pose{};
  pose.utime = utime;
  pose.frame = wingman::own_pose_t::FRAME_ENU;
  pose.q_body_to_world[0] = 1.0;
  localizer_->on_own_pose(pose);

  // Every box as wingman-detector publishes it (detector::to_detection: unclipped, every class); the Localizer tracks
  // class 0 (drone) only and counts the others, or with classes.decision "track" tracks every box.
  wingman::detections_t d{};
  d.utime = utime;
  d.seq = frame_index;
  d.camera_id = options_.camera.camera_id;
  d.image_width = camera_.width();
  d.image_height = camera_.height();
  d.source = wingman::detections_t::SOURCE_CNN;
  std::vector<const detector::Box*> drone;  // the boxes the Localizer tracks
  const bool track_every_class = options_.class_decision == "track";
  for (const detector::Box& b : boxes) {
    d.detections.push_back(detector::to_detection(b));
    if (b.class_id == common::kDroneClassId) ++drone_boxes_;
    if (b.class_id == common::kDroneClassId || track_every_class) drone.push_back(&b);
  }
  d.num_detections = static_cast<int32_t>(d.detections.size());

  const localizer::LocalizerOutput out = localizer_->on_detections(d);
  other_class_boxes_ += out.non_drone.total;
  for (const std::string& why : out.rejections)
    if (why.rfind("detections_t.detections[", 0) == 0) ++rejected_boxes_;
  if (!out.targets) return;

  // The same localization the Localizer made of each box (deterministic: the same numbers), to find which box a
  // track took in this frame from the camera-frame position it reports.
  std::vector<Eigen::Vector3d> p_in_cam(drone.size(),
                                        Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  for (size_t i = 0; i < drone.size(); ++i) {
    const geometry::PixelBox box{drone[i]->cx, drone[i]->cy, drone[i]->w, drone[i]->h};
    const localizer::LocalizeResult r = localizer::localize_box(
        box, camera_, options_.sphere, relation_.at(box.w, box.h, static_cast<double>(camera_.width())));
    if (r.ok && r.measurement.range_valid) p_in_cam[i] = r.measurement.p_target_in_cam;
  }
  for (const wingman::target_t& t : out.targets->targets) {
    if (t.track_id <= 0) continue;
    auto [it, fresh] = tracks_.try_emplace(t.track_id);
    TrackRecord& rec = it->second;
    if (fresh) {
      rec.track_id = t.track_id;
      rec.confirmed_frame = frame_index;
    }
    rec.last_frame = frame_index;
    if (t.source_utime != utime) continue;  // coasting: no detection this frame
    const Eigen::Vector3d p = geometry::to_vector3(t.p_target_in_cam);
    size_t best = drone.size();
    double best_d = std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < drone.size(); ++i) {
      const double dist = (p_in_cam[i] - p).norm();
      if (dist < best_d) best_d = dist, best = i;
    }
    ++rec.hits;
    if (best == drone.size() || !(best_d <= 1e-6 * std::max(1.0, p.norm()))) continue;  // not found: not on target
    const detector::Box& b = *drone[best];
    if (std::any_of(drone_truths.begin(), drone_truths.end(),
                    [&](const cv::Rect2d& r) { return centre_inside(b.cx, b.cy, r); }))
      ++rec.hits_on_target;
  }
}

std::vector<TrackRecord> ClipTracker::tracks() const {
  std::vector<TrackRecord> v;
  for (const auto& [id, rec] : tracks_) v.push_back(rec);
  return v;
}

void score_clip(ClipTrackResult& clip, const TrackScoringOptions& scoring) {
  clip.false_tracks = 0;
  clip.drone_tracks = 0;
  clip.drone_confirmed = false;
  clip.time_to_confirm_s = -1;
  int first_on_target = std::numeric_limits<int>::max();
  for (TrackRecord& t : clip.tracks) {
    t.on_target = t.hits > 0 && t.hits_on_target > scoring.on_target_fraction * t.hits;
    if (!t.on_target) {
      ++clip.false_tracks;
    } else {
      ++clip.drone_tracks;
      first_on_target = std::min(first_on_target, t.confirmed_frame);
    }
  }
  if (first_on_target != std::numeric_limits<int>::max() && clip.fps > 0) {
    clip.drone_confirmed = true;
    const int from = std::max(0, clip.first_label_frame);
    clip.time_to_confirm_s = std::max(0.0, (first_on_target - from) / clip.fps);
  }
}

// ---------------------------------------------------------------------------------------------------------------------
// Labels, summary

std::map<int, std::vector<cv::Rect2d>> read_halmstad_drone_boxes(const std::string& path) {
  std::map<int, std::vector<cv::Rect2d>> boxes;
  for (const auto& [frame, labels] : read_halmstad_labels(path))
    for (const HalmstadLabelBox& label : labels)
      if (label.cls == 0) boxes[frame].push_back(label.rect);
  return boxes;
}

int SequenceEvalResult::skipped() const {
  return static_cast<int>(
      std::count_if(clips.begin(), clips.end(), [](const ClipTrackResult& c) { return !c.skipped.empty(); }));
}

std::vector<TrackGroupSummary> SequenceEvalResult::groups() const {
  std::vector<TrackGroupSummary> out;
  auto make = [&](const std::string& name, bool drone, const std::function<bool(const ClipTrackResult&)>& member) {
    TrackGroupSummary g;
    g.name = name;
    g.drone = drone;
    double seconds = 0;
    std::vector<double> times;
    for (const ClipTrackResult& c : clips) {
      if (!c.skipped.empty() || !member(c)) continue;
      ++g.clips;
      seconds += c.duration_s;
      g.false_tracks += c.false_tracks;
      g.drone_tracks += c.drone_tracks;
      if (drone && c.drone_confirmed) {
        ++g.confirmed;
        times.push_back(c.time_to_confirm_s);
        if (c.time_to_confirm_s <= scoring.confirm_within_s + 1e-9) ++g.confirmed_within;
      }
    }
    if (g.clips == 0) return;
    g.hours = seconds / 3600.0;
    g.false_per_hour = g.hours > 0 ? g.false_tracks / g.hours : 0.0;
    g.false_per_hour_upper95 = g.hours > 0 ? poisson_upper95(g.false_tracks) / g.hours : 0.0;
    g.median_time_to_confirm_s = median(times);
    out.push_back(g);
  };
  for (const std::string& bin : kDistanceBins)
    make("DRONE " + bin, true, [&](const ClipTrackResult& c) { return c.cls == "DRONE" && c.distance_bin == bin; });
  // Bins other than the three known ones, if a split lists any.
  std::set<std::string> other_bins;
  for (const ClipTrackResult& c : clips)
    if (c.cls == "DRONE" &&
        std::find(kDistanceBins.begin(), kDistanceBins.end(), c.distance_bin) == kDistanceBins.end())
      other_bins.insert(c.distance_bin);
  for (const std::string& bin : other_bins)
    make("DRONE " + bin, true, [&](const ClipTrackResult& c) { return c.cls == "DRONE" && c.distance_bin == bin; });
  make("DRONE", true, [](const ClipTrackResult& c) { return c.cls == "DRONE"; });
  for (size_t k = 1; k < kHalmstadClasses.size(); ++k)
    make(kHalmstadClasses[k], false, [&](const ClipTrackResult& c) { return c.cls == kHalmstadClasses[k]; });
  make("distractors", false, [](const ClipTrackResult& c) { return c.cls != "DRONE"; });
  return out;
}

std::string SequenceEvalResult::report() const {
  const int n_skipped = skipped();
  std::string s = fmt::format(
      "track-level metrics: {} clips of split '{}' ({} skipped), {} through the detector and wingman-localizer's "
      "tracker; static camera, pinhole HFOV {:.1f} deg (fx {:.1f} px); a track is on the drone when > {:.0f} % of its "
      "confirmed hits have their box centre in a labelled drone box\n",
      clips.size() - static_cast<size_t>(n_skipped), split, n_skipped,
      (frame_step == 1 ? std::string("every frame") : fmt::format("every {}th frame", frame_step)) +
          (max_seconds > 0 ? fmt::format(" of each clip's first {:g} s", max_seconds) : std::string()),
      hfov_deg, focal_px, 100.0 * scoring.on_target_fraction);
  s += fmt::format("  {:<14} {:>5} {:>8} {:>6} {:>8} {:>9} {:>15} {:>12} {:>10} {:>10}\n", "clips", "n", "video h",
                   "false", "false/h", "(95% up)", "drone confirmed",
                   fmt::format("within {:g} s", scoring.confirm_within_s), "median s", "drone ids");
  const std::vector<TrackGroupSummary> gs = groups();
  for (const TrackGroupSummary& g : gs) {
    std::string confirmed = "", within = "", med = "", ids = "";
    if (g.drone) {
      ids = fmt::format("{}", g.drone_tracks);
      confirmed = fmt::format("{}/{} {:.0f}%", g.confirmed, g.clips, 100.0 * g.confirmed / g.clips);
      within = fmt::format("{}/{} {:.0f}%", g.confirmed_within, g.clips, 100.0 * g.confirmed_within / g.clips);
      med = g.median_time_to_confirm_s < 0 ? "-" : fmt::format("{:.2f}", g.median_time_to_confirm_s);
    }
    std::string row =
        fmt::format("  {:<14} {:>5} {:>8.4f} {:>6} {:>8.1f} {:>9.1f} {:>15} {:>12} {:>10} {:>10}", g.name, g.clips,
                    g.hours, g.false_tracks, g.false_per_hour, g.false_per_hour_upper95, confirmed, within, med, ids);
    row.erase(row.find_last_not_of(' ') + 1);  // distractor rows have no drone columns
    s += row + "\n";
  }
  for (const TrackGroupSummary& g : gs) {
    if (g.name == "distractors")
      s += fmt::format("target <= 1 false track per hour of distractor video: {:.1f} per hour ({} in {:.3f} h): {}\n",
                       g.false_per_hour, g.false_tracks, g.hours, g.false_per_hour <= 1.0 ? "met" : "not met");
    if (g.name == "DRONE")
      s += fmt::format("target >= 95 % of drone clips confirmed within {:g} s: {:.1f} % ({} of {}): {}\n",
                       scoring.confirm_within_s, 100.0 * g.confirmed_within / g.clips, g.confirmed_within, g.clips,
                       g.confirmed_within >= 0.95 * g.clips ? "met" : "not met");
  }
  std::string false_list, late_list, skip_list;
  for (const ClipTrackResult& c : clips) {
    if (!c.skipped.empty()) {
      skip_list += fmt::format("    {}: {}\n", c.clip, c.skipped);
      continue;
    }
    for (const TrackRecord& t : c.tracks)
      if (!t.on_target)
        false_list += fmt::format("    {} ({}{}): track {} confirmed at {:.2f} s (frame {}), {} hits, {} on a drone\n",
                                  c.clip, c.cls, c.cls == "DRONE" ? " " + c.distance_bin : "", t.track_id,
                                  t.confirmed_frame / c.fps, t.confirmed_frame, t.hits, t.hits_on_target);
    if (c.cls == "DRONE" && !(c.drone_confirmed && c.time_to_confirm_s <= scoring.confirm_within_s + 1e-9))
      late_list += fmt::format(
          "    {} ({}): {}; {} drone boxes detected, {} rejected by the localizer\n", c.clip, c.distance_bin,
          c.drone_confirmed ? fmt::format("confirmed after {:.2f} s", c.time_to_confirm_s) : "never confirmed",
          c.drone_boxes, c.rejected_boxes);
  }
  if (!false_list.empty()) s += "false tracks:\n" + false_list;
  if (!late_list.empty())
    s += fmt::format("drone clips not confirmed within {:g} s:\n", scoring.confirm_within_s) + late_list;
  if (!skip_list.empty()) s += "skipped clips:\n" + skip_list;
  if (motion.frames > 0) {
    s += fmt::format(
        "motion cue: {} of {} frames compared ({} not aligned, {} restarts), {} moving blobs, "
        "{} windows searched in {} crops, {} found a drone\n",
        motion.compared, motion.frames, motion.unaligned, motion.restarts, motion.blobs, motion_windows.windows,
        motion_windows.crops, motion_windows.found);
  }
  return s;
}

std::string SequenceEvalResult::json() const {
  using common::Json;
  Json groups_json = Json::array();
  for (const TrackGroupSummary& g : groups()) {
    Json gj;
    gj["name"] = g.name;
    gj["drone"] = g.drone;
    gj["clips"] = g.clips;
    gj["hours"] = g.hours;
    gj["false_tracks"] = g.false_tracks;
    gj["false_tracks_per_hour"] = g.false_per_hour;
    gj["false_tracks_per_hour_upper95"] = g.false_per_hour_upper95;
    if (g.drone) {
      gj["drone_tracks"] = g.drone_tracks;
      gj["confirmed"] = g.confirmed;
      gj["confirmed_share"] = static_cast<double>(g.confirmed) / g.clips;
      gj["confirmed_within"] = g.confirmed_within;
      gj["confirmed_within_share"] = static_cast<double>(g.confirmed_within) / g.clips;
      gj["median_time_to_confirm_s"] = seconds_or_null(g.median_time_to_confirm_s);
    }
    groups_json.push_back(std::move(gj));
  }
  Json clips_json = Json::array();
  for (const ClipTrackResult& c : clips) {
    Json tracks = Json::array();
    for (const TrackRecord& t : c.tracks)
      tracks.push_back({{"id", t.track_id},
                        {"confirmed_frame", t.confirmed_frame},
                        {"confirmed_s", c.fps > 0 ? t.confirmed_frame / c.fps : 0.0},
                        {"last_frame", t.last_frame},
                        {"hits", t.hits},
                        {"hits_on_target", t.hits_on_target},
                        {"on_target", t.on_target}});
    Json cj;
    cj["clip"] = c.clip;
    cj["class"] = c.cls;
    cj["distance_bin"] = c.distance_bin;
    cj["skipped"] = c.skipped.empty() ? Json(nullptr) : Json(c.skipped);
    cj["fps"] = c.fps;
    cj["frames"] = c.frames;
    cj["frames_tracked"] = c.frames_tracked;
    cj["duration_s"] = c.duration_s;
    cj["first_label_frame"] = c.first_label_frame;
    cj["drone_boxes"] = c.drone_boxes;
    cj["other_class_boxes"] = c.other_class_boxes;
    cj["rejected_boxes"] = c.rejected_boxes;
    cj["false_tracks"] = c.false_tracks;
    cj["drone_tracks"] = c.drone_tracks;
    cj["drone_confirmed"] = c.drone_confirmed;
    cj["time_to_confirm_s"] = seconds_or_null(c.time_to_confirm_s);
    cj["tracks"] = std::move(tracks);
    clips_json.push_back(std::move(cj));
  }
  Json j;
  j["split"] = split;
  j["hfov_deg"] = hfov_deg;
  j["focal_px"] = focal_px;
  j["frame_step"] = frame_step;
  j["max_seconds"] = max_seconds;
  j["on_target_fraction"] = scoring.on_target_fraction;
  j["confirm_within_s"] = scoring.confirm_within_s;
  j["skipped"] = skipped();
  j["groups"] = std::move(groups_json);
  j["clips"] = std::move(clips_json);
  if (motion.frames > 0) {
    j["motion"] = {{"frames", motion.frames},       {"compared", motion.compared},
                   {"unaligned", motion.unaligned}, {"restarts", motion.restarts},
                   {"blobs", motion.blobs},         {"windows_searched", motion_windows.windows},
                   {"crops", motion_windows.crops}, {"found", motion_windows.found}};
  }
  return common::json_text(j);
}

// ---------------------------------------------------------------------------------------------------------------------
// The run

namespace {
constexpr const char* kBoxesMagic = "# wingman val --sequences boxes v1";
constexpr int kMaxCachedFrames = 10000000;  // about 93 h at 30 frames/s: a clip, never a loop of billions of frames
}  // namespace

void write_clip_boxes(const std::string& path, const ClipBoxes& b) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream f(tmp, std::ios::trunc);
    if (!f) throw std::runtime_error(fmt::format("{}: cannot write the boxes cache file", tmp));
    f << kBoxesMagic << "\n"
      << "settings " << b.settings << "\n"
      << fmt::format("video {:.17g} {} {} {} {}\n", b.fps, b.frames, b.width, b.height, b.frame_step);
    for (const auto& [frame, boxes] : b.boxes)
      for (const detector::Box& x : boxes)
        f << fmt::format("{} {} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {:.9g} {}\n", frame, x.class_id, x.confidence,
                         x.drone_score, x.cx, x.cy, x.w, x.h, static_cast<int>(x.pass));
    if (!f.flush()) throw std::runtime_error(fmt::format("{}: cannot write the boxes cache file", tmp));
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) throw std::runtime_error(fmt::format("{}: cannot rename to {}: {}", tmp, path, ec.message()));
}

ClipBoxes read_clip_boxes(const std::string& path) {
  std::ifstream f(path);
  if (!f) throw DatasetError(fmt::format("{}: cannot open the boxes cache file", path));
  std::string line;
  int n = 0;
  auto fail = [&](const std::string& why) { throw DatasetError(fmt::format("{}:{}: {}", path, n, why)); };
  ClipBoxes b;
  if (!std::getline(f, line) || (++n, line != kBoxesMagic))
    fail(fmt::format("not a boxes cache file (the first line must be '{}')", kBoxesMagic));
  if (!std::getline(f, line) || (++n, line.rfind("settings ", 0) != 0)) fail("expected 'settings <what made them>'");
  b.settings = line.substr(9);
  if (!std::getline(f, line)) fail("expected 'video <fps> <frames> <width> <height> <frame_step>'");
  ++n;
  {
    std::istringstream in(line);
    std::string word;
    if (!(in >> word >> b.fps >> b.frames >> b.width >> b.height >> b.frame_step) || word != "video" ||
        !(in >> std::ws).eof())
      fail("expected 'video <fps> <frames> <width> <height> <frame_step>'");
    if (!(b.fps > 0.0 && b.fps <= 1000.0) || b.frames < 0 || b.frames > kMaxCachedFrames || b.frame_step < 1 ||
        (b.frames > 0 && (b.width <= 0 || b.height <= 0)))
      fail(
          fmt::format("video {} {} {} {} {}: needs fps in (0, 1000], frames in [0, {}], a positive size, "
                      "frame_step >= 1",
                      b.fps, b.frames, b.width, b.height, b.frame_step, kMaxCachedFrames));
  }
  while (std::getline(f, line)) {
    ++n;
    if (blank(line)) continue;
    std::istringstream in(line);
    int frame = 0, pass = 0;
    detector::Box x;
    if (!(in >> frame >> x.class_id >> x.confidence >> x.drone_score >> x.cx >> x.cy >> x.w >> x.h >> pass) ||
        !(in >> std::ws).eof())
      fail("expected '<frame> <class> <confidence> <drone_score> <cx> <cy> <w> <h> <pass 0|1|2>'");
    if (frame < 0 || frame >= b.frames || frame % b.frame_step != 0)
      fail(fmt::format("frame {}: not a tracked frame of {} (frame_step {})", frame, b.frames, b.frame_step));
    if (x.class_id < 0 || !(x.w >= 0.0f && std::isfinite(x.w)) || !(x.h >= 0.0f && std::isfinite(x.h)) ||
        !std::isfinite(x.cx) || !std::isfinite(x.cy) || !(x.confidence >= 0.0f && x.confidence <= 1.0f) ||
        !(x.drone_score >= 0.0f && x.drone_score <= 1.0f) || pass < 0 || pass > 2)
      fail(
          "a box needs class >= 0, scores in [0, 1], finite centre, w, h >= 0 and pass 0 (single), 1 (zoom-in) or 2 "
          "(window)");
    x.pass = static_cast<detector::Pass>(pass);
    b.boxes[frame].push_back(x);
  }
  return b;
}

/// The motion cue's settings as a cache key (" motion=..."), when it is on.
std::string motion_settings(const SequenceEvalOptions& o) {
  const detector::MotionOptions& m = o.motion;
  const detector::WindowOptions& w = o.windows;
  return fmt::format(
      " motion=scale:{},lag:{},sigma:{},min_diff:{},min_contrast:{},max_blob:{}/{},repeat:{},windows:{},gap:{},"
      "border:{},window_sigma:{},max_shift:{} crop_px={} window_p_thresh={} gate_sigma={}",
      m.scale, m.lag_frames, m.threshold_sigma, m.min_difference, m.min_contrast, m.max_blob_px, m.max_blob_side_px,
      m.repeat_radius_px, m.max_windows, m.max_gap_s, m.border_px, m.sigma_px, m.max_shift_fraction, w.crop_px,
      w.p_thresh, w.gate_sigma);
}

std::string detection_settings(const SequenceEvalOptions& o) {
  const detector::DetectorPipelineOptions& d = o.detection;
  // A cfg file is keyed by its bytes' SHA-256 too (a built-in one by its name).
  const std::string cfg_id =
      o.cfg.rfind("builtin:", 0) == 0 ? std::string("builtin") : detector::weights_model_id(o.cfg);
  return fmt::format(
             "cfg={} cfg_sha256={} weights_sha256={} backend={} input_size={} p_thresh={} o_thresh={} subsquare={} "
             "zoom_in={} zoom_max_fraction={} flip_fusion={} fusion_iou={} coarse_pass={} coarse_scale={} "
             "coarse_min_size={} drone_first={} policy={} max_detections={}",
             o.cfg, cfg_id, detector::weights_model_id(o.weights), o.backend, o.input_size, d.p_thresh, d.o_thresh,
             d.subsquare, d.zoom_in, d.zoom_max_fraction, d.flip_fusion, d.fusion_iou, d.coarse_pass, d.coarse_scale,
             d.coarse_min_size, d.drone_first, d.policy, d.max_detections) +
         (o.motion.enabled ? motion_settings(o) : std::string());
}

SequenceEvalResult run_sequence_eval(const SequenceEvalOptions& o, const FrameDetector& detect_in,
                                     const std::function<void(const std::string&)>& log,
                                     const std::function<void(size_t, size_t)>& progress) {
  const std::vector<std::string> problems = o.validate();
  if (!problems.empty()) {
    std::string msg = "run_sequence_eval: invalid options:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
  if (o.motion.enabled && detect_in)
    throw std::invalid_argument(
        "run_sequence_eval: motion.enabled needs the built-in detector (its window network searches the motion cue's "
        "windows); a given FrameDetector has none");
  // splits.csv beside the data.yaml, or in the folder.
  const fs::path data(o.data);
  if (!fs::exists(data))
    throw DatasetError(
        fmt::format("{}: no such folder or file: give the folder `wingman import-halmstad` wrote "
                    "(splits.csv) or its data.yaml",
                    o.data));
  const fs::path folder = fs::is_directory(data) ? data : data.parent_path();
  const std::string splits_path = (folder / "splits.csv").string();
  std::vector<SplitClip> clips = read_splits(splits_path, o.split);
  if (clips.empty()) throw DatasetError(fmt::format("{}: no clip is in split '{}'", splits_path, o.split));
  if (!o.clips.empty()) {
    std::vector<SplitClip> chosen;
    for (const std::string& name : o.clips) {
      const auto it = std::find_if(clips.begin(), clips.end(), [&](const SplitClip& c) { return c.name == name; });
      if (it == clips.end())
        throw DatasetError(fmt::format("{}: clip '{}' is not in split '{}'", splits_path, name, o.split));
      chosen.push_back(*it);
    }
    std::sort(chosen.begin(), chosen.end(), [](const SplitClip& a, const SplitClip& b) { return a.name < b.name; });
    chosen.erase(std::unique(chosen.begin(), chosen.end(),
                             [](const SplitClip& a, const SplitClip& b) { return a.name == b.name; }),
                 chosen.end());
    clips = chosen;
  }
  const fs::path root(o.halmstad_root);
  if (!fs::is_directory(root / "videos") || !fs::is_directory(root / "labels"))
    throw DatasetError(
        fmt::format("{}: not the Halmstad dataset folder (no videos/ and labels/ in it)", o.halmstad_root));

  localizer::LocalizerOptions loc_options;
  if (!o.localizer_config.empty()) loc_options = common::load_options<localizer::LocalizerOptions>(o.localizer_config);

  // The detector, as `wingman val` builds it, unless one is given; built on the first clip that needs it (a run
  // wholly from the boxes cache never loads it).
  FrameDetector detect = detect_in;
  std::shared_ptr<detector::SizedDetector> pipeline;
  std::shared_ptr<detector::WindowDetector> windows;  // the motion cue's window network (motion.enabled)
  detector::WindowOptions motion_windows = o.windows;
  motion_windows.max_per_frame = o.motion.max_windows;
  auto detector_for_frames = [&]() -> FrameDetector& {
    if (!detect) {
      auto make_backend = [&](const detector::DarknetModel& sized) {
        std::string why;
        auto backend = detector::make_backend(o.backend, sized, detector::OpenClOptions{}, 1, &why,
                                              detector::AutoChoice::kRepeatable);
        if (log) log(fmt::format("{} (network input {}x{})", why, sized.net.width, sized.net.height));
        return backend;
      };
      const detector::DarknetModel model = detector::load_model(o.cfg, o.weights);
      pipeline = std::make_shared<detector::SizedDetector>(o.detection, model,
                                                           *detector::InputSize::parse(o.input_size), make_backend);
      detect = [pipeline](const cv::Mat& bgr) { return pipeline->detect(bgr); };
      if (o.motion.enabled)
        windows = std::make_shared<detector::WindowDetector>(o.windows, o.detection, model, make_backend);
    }
    return detect;
  };
  std::string settings;
  if (!o.boxes_cache.empty()) {
    settings = detect_in ? std::string("custom detector") : detection_settings(o);
    std::error_code ec;
    fs::create_directories(o.boxes_cache, ec);
    if (!fs::is_directory(o.boxes_cache))
      throw std::runtime_error(fmt::format("{}: cannot create the boxes cache folder", o.boxes_cache));
  }

  SequenceEvalResult result;
  result.split = o.split;
  result.hfov_deg = o.hfov_deg;
  result.frame_step = o.frame_step;
  result.max_seconds = o.max_seconds;
  result.scoring = o.scoring;
  // Frame k is tracked only while its video time k / fps is before max_seconds (when set).
  const auto before_limit = [&o](int k, double fps) { return o.max_seconds <= 0 || k < o.max_seconds * fps; };
  for (const SplitClip& sc : clips) {
    ClipTrackResult c;
    c.clip = sc.name, c.cls = sc.cls, c.distance_bin = sc.distance_bin;
    // Labels first: a bad label file is an error naming it, before any frame is spent.
    const std::string label_path = (root / "labels" / (sc.name + ".csv")).string();
    const std::map<int, std::vector<cv::Rect2d>> truths = read_halmstad_drone_boxes(label_path);
    c.first_label_frame = truths.empty() ? -1 : truths.begin()->first;

    const std::string video = (root / "videos" / (sc.name + ".mp4")).string();
    const std::string cache_path =
        o.boxes_cache.empty() ? std::string() : (fs::path(o.boxes_cache) / (sc.name + ".boxes")).string();
    std::unique_ptr<ClipTracker> tracker;
    // The clip's tracker, on the nominal pinhole of its frame size (the first clip's focal length is reported).
    const auto start_tracker = [&](int width, int height, double fps) {
      const geometry::CameraModel camera = nominal_pinhole(width, height, o.hfov_deg);
      if (result.focal_px == 0) result.focal_px = camera.fx();
      return std::make_unique<ClipTracker>(loc_options, camera, fps);
    };
    static const std::vector<cv::Rect2d> kNone;
    auto truths_at = [&](int k) -> const std::vector<cv::Rect2d>& {
      const auto it = truths.find(k);
      return it == truths.end() ? kNone : it->second;
    };
    if (!cache_path.empty() && fs::exists(cache_path)) {
      // Tracked from the cache: the same boxes the detector gave when the file was written.
      const ClipBoxes cached = read_clip_boxes(cache_path);
      if (cached.settings != settings)
        throw DatasetError(
            fmt::format("{}: made with other detection settings: the file has '{}', this run '{}' "
                        "(remove the file or use another --boxes-cache)",
                        cache_path, cached.settings, settings));
      if (cached.frame_step != o.frame_step)
        throw DatasetError(
            fmt::format("{}: made with frame_step {}, this run {}", cache_path, cached.frame_step, o.frame_step));
      c.fps = cached.fps;
      c.frames = cached.frames;
      if (o.max_seconds > 0) c.frames = std::min(c.frames, static_cast<int>(std::ceil(o.max_seconds * c.fps - 1e-9)));
      if (c.frames == 0) c.skipped = fmt::format("{}: no frame could be read", video);
      static const std::vector<detector::Box> kNoBoxes;
      for (int k = 0; k < c.frames && c.skipped.empty(); k += o.frame_step) {
        if (!tracker) tracker = start_tracker(cached.width, cached.height, c.fps);
        const auto it = cached.boxes.find(k);
        tracker->add_frame(k, it == cached.boxes.end() ? kNoBoxes : it->second, truths_at(k));
      }
    } else {
      cv::VideoCapture cap;
      // FFmpeg only: the Halmstad clips are MP4 files it reads; OpenCV's fallback to GStreamer on an unreadable file
      // adds nothing here (and leaks in GStreamer's device probing, libusb).
      if (fs::is_regular_file(video)) cap.open(video, cv::CAP_FFMPEG);
      if (!cap.isOpened()) {
        c.skipped = fmt::format("{}: cannot open the video", video);
      } else {
        c.fps = cap.get(cv::CAP_PROP_FPS);
        if (!(c.fps > 0.0) || !std::isfinite(c.fps) || c.fps > 1000.0)
          c.skipped = fmt::format("{}: the video gives no usable frame rate ({})", video, c.fps);
      }
      if (c.skipped.empty()) {
        ClipBoxes record;
        record.settings = settings;
        record.fps = c.fps;
        record.frame_step = o.frame_step;
        cv::Mat frame;
        // The motion cue sees this clip's frames only, at their video times.
        std::optional<detector::MotionCue> cue;
        if (o.motion.enabled) cue.emplace(o.motion);
        for (int k = 0; before_limit(k, c.fps); ++k) {
          if (k % o.frame_step != 0) {
            if (!cap.grab()) break;
            ++c.frames;
            continue;
          }
          if (!cap.read(frame) || frame.empty()) break;
          ++c.frames;
          if (!tracker) {
            tracker = start_tracker(frame.cols, frame.rows, c.fps);
            record.width = frame.cols, record.height = frame.rows;
          } else if (frame.cols != tracker->camera().width() || frame.rows != tracker->camera().height()) {
            c.skipped = fmt::format("{}: frame {} is {}x{}, the first {}x{}", video, k, frame.cols, frame.rows,
                                    tracker->camera().width(), tracker->camera().height());
            break;
          }
          std::vector<detector::Box> boxes = detector_for_frames()(frame);
          if (cue && windows) {
            const auto utime = static_cast<int64_t>(std::llround(k * 1e6 / c.fps));
            const std::vector<detector::Window> moving = cue->windows(frame, utime, boxes);
            if (!moving.empty())
              boxes = windows->detect(frame, std::move(boxes), moving, motion_windows, &result.motion_windows);
          }
          tracker->add_frame(k, boxes, truths_at(k));
          if (!boxes.empty()) record.boxes[k] = std::move(boxes);
        }
        if (cue) {
          result.motion.frames += cue->stats().frames;
          result.motion.compared += cue->stats().compared;
          result.motion.blobs += cue->stats().blobs;
          result.motion.windows += cue->stats().windows;
          result.motion.unaligned += cue->stats().unaligned;
          result.motion.restarts += cue->stats().restarts;
        }
        if (c.skipped.empty() && c.frames == 0) c.skipped = fmt::format("{}: no frame could be read", video);
        record.frames = c.frames;
        // Only a whole clip is cached (a skipped one is tried again next time; a time limit leaves the clip's end).
        if (!cache_path.empty() && c.skipped.empty() && o.max_seconds <= 0) write_clip_boxes(cache_path, record);
      }
    }
    if (tracker) {
      c.frames_tracked = tracker->frames();
      c.tracks = tracker->tracks();
      c.drone_boxes = tracker->drone_boxes();
      c.other_class_boxes = tracker->other_class_boxes();
      c.rejected_boxes = tracker->rejected_boxes();
    }
    c.duration_s = c.fps > 0 ? c.frames / c.fps : 0.0;
    if (c.skipped.empty()) {
      score_clip(c, o.scoring);
    } else {
      c.tracks.clear();
    }
    if (log) {
      if (!c.skipped.empty()) {
        log(fmt::format("{} ({} {}): skipped: {}", c.clip, c.cls, c.distance_bin, c.skipped));
      } else {
        std::string drone;
        if (c.cls == "DRONE")
          drone = c.drone_confirmed ? fmt::format(", drone confirmed after {:.2f} s", c.time_to_confirm_s)
                                    : ", drone not confirmed";
        log(
            fmt::format("{} ({} {}): {} frames, {} drone boxes ({} rejected by the localizer), {} confirmed tracks, {} "
                        "false{}",
                        c.clip, c.cls, c.distance_bin, c.frames, c.drone_boxes, c.rejected_boxes, c.tracks.size(),
                        c.false_tracks, drone));
      }
    }
    result.clips.push_back(std::move(c));
    if (progress) progress(result.clips.size(), clips.size());
  }
  return result;
}

}  // namespace wingman::training
