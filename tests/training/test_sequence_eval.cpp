// SPDX-License-Identifier: MIT
// Track-level metrics (`wingman val --sequences`): a synthetic sequence fed to the real tracker with hand-computed
// confirmations and false tracks, the per-hour rates and the groups, a generated video end to end, bad input, and one
// real Halmstad clip with the shipped model (skipped without ../shared).
#include <wingman/common/config.hpp>
#include <wingman/training/sequence_eval.hpp>
#include <wingman/training/yolo_dataset.hpp>

#include "hand_case.hpp"
#include "test_support.hpp"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <vector>

namespace wingman::training {
namespace {

namespace fs = std::filesystem;

constexpr double kFps = 30.0;

detector::Box box(float cx, float cy, float w, float h, int class_id = 0) {
  detector::Box b;
  b.cx = cx, b.cy = cy, b.w = w, b.h = h;
  b.confidence = 0.9f;
  b.class_id = class_id;
  b.drone_score = class_id == 0 ? b.confidence : 0.05f;
  return b;
}

/// The localizer with the 3-of-5 birth rule and no confidence bar: the frame counts the ClipTracker tests compute by
/// hand (the end-to-end test below uses the defaults).
localizer::LocalizerOptions three_of_five() {
  localizer::LocalizerOptions o;
  o.tracker.birth_hits = 3;
  o.tracker.birth_window = 5;
  o.tracker.confirm_min_confidence = 0.0;
  return o;
}

template <class F>
std::string error_of(F&& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(SequenceEvalOptions, DefaultsAreValidOnceDataIsGivenAndBadFieldsAreNamed) {
  SequenceEvalOptions o;
  EXPECT_EQ(o.detection.p_thresh, 0.2);  // what wingman-detector publishes, not val's 0.005 curve floor
  EXPECT_EQ(o.hfov_deg, 24.0);
  o.data = "d";
  EXPECT_TRUE(o.validate().empty());
  o.hfov_deg = 180;
  o.frame_step = 0;
  o.max_seconds = -1;
  o.scoring.on_target_fraction = 1;
  o.scoring.confirm_within_s = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 5u);
  EXPECT_NE(p[0].find("hfov_deg = 180"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("frame_step = 0"), std::string::npos) << p[1];
  EXPECT_NE(p[2].find("max_seconds = -1: must be >= 0"), std::string::npos) << p[2];
  EXPECT_NE(p[3].find("scoring.on_target_fraction = 1"), std::string::npos) << p[3];
  EXPECT_NE(p[4].find("scoring.confirm_within_s = 0"), std::string::npos) << p[4];
  const std::string e = error_of([&] { run_sequence_eval(o); });
  EXPECT_EQ(e.rfind("run_sequence_eval: invalid options:", 0), 0u) << e;
}

TEST(SequenceEvalOptions, TheMotionCueIsCheckedWhenOnAndIsPartOfTheBoxesCacheKey) {
  SequenceEvalOptions o;
  o.data = "d";
  o.motion.lag_frames = 0;  // bad, but off: not checked
  EXPECT_TRUE(o.validate().empty());
  const std::string off = detection_settings(o);
  o.motion.enabled = true;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p[0].rfind("motion.lag_frames = 0", 0), 0u) << p[0];
  o.motion.lag_frames = 10;
  EXPECT_NE(detection_settings(o), off);  // boxes cached without the cue are not reused with it
  EXPECT_NE(detection_settings(o).find("motion="), std::string::npos);
  const std::string e =
      error_of([&] { run_sequence_eval(o, [](const cv::Mat&) { return std::vector<detector::Box>{}; }); });
  EXPECT_NE(e.find("motion.enabled needs the built-in detector"), std::string::npos) << e;
}

TEST(NominalPinhole, FocalLengthFromTheFieldOfView) {
  // 90 deg over 640 px: f = 320 / tan(45 deg) = 320 px; 24 deg: 320 / tan(12 deg) = 1505.48 px.
  EXPECT_NEAR(nominal_pinhole(640, 512, 90.0).fx(), 320.0, 1e-9);
  const geometry::CameraModel c = nominal_pinhole(640, 512, 24.0);
  EXPECT_NEAR(c.fx(), 1505.4816, 1e-4);
  EXPECT_NEAR(c.fy(), c.fx(), 1e-12);
  EXPECT_EQ(c.width(), 640);
  EXPECT_EQ(c.height(), 512);
  EXPECT_THROW(nominal_pinhole(0, 512, 24.0), std::invalid_argument);
  EXPECT_THROW(nominal_pinhole(640, 512, 0.0), std::invalid_argument);
}

// 60 frames (2 s at 30 fps) of a 640x512 camera, through the real Localizer with its default options (M = 3 of N = 5):
// - the drone, labelled from frame 6, detected at 6, then missed at 7 and 8, then every frame 9..59: its tentative
// track
//   has 3 hits in its first 5 frames (6..10) at frame 10, so it is confirmed there, (10 - 6) / 30 s after its first
//   label, and keeps 50 hits (10..59), all with the box centre in the label;
// - a static false box at (500, 400), frames 20..39: confirmed at 22 (third hit), 18 hits (22..39), none on a drone;
// - four scattered single false boxes: never 3 hits, never confirmed;
// - a class-1 box every frame: not tracked;
// - a 1x1-px class-0 box at frames 50..54: its range (about 1000 m) is beyond range.max_m, the localizer rejects it.
TEST(ClipTracker, SyntheticSequenceGivesTheHandComputedTracks) {
  ClipTracker tracker(three_of_five(), nominal_pinhole(640, 512, 24.0), kFps);
  const cv::Rect2d label(185, 140, 30, 20);  // contains the drone box's centre (200, 150)
  for (int f = 0; f < 60; ++f) {
    std::vector<detector::Box> boxes;
    if (f == 6 || f >= 9) boxes.push_back(box(200, 150, 20, 16));
    if (f >= 20 && f < 40) boxes.push_back(box(500, 400, 20, 16));
    if (f == 0) boxes.push_back(box(100, 450, 20, 16));
    if (f == 3) boxes.push_back(box(600, 50, 20, 16));
    if (f == 30) boxes.push_back(box(320, 256, 20, 16));
    if (f == 45) boxes.push_back(box(50, 50, 20, 16));
    boxes.push_back(box(400, 100, 30, 12, 1));
    if (f >= 50 && f < 55) boxes.push_back(box(300, 300, 1, 1));
    tracker.add_frame(f, boxes, f >= 6 ? std::vector<cv::Rect2d>{label} : std::vector<cv::Rect2d>{});
  }
  EXPECT_EQ(tracker.frames(), 60);
  EXPECT_EQ(tracker.other_class_boxes(), 60);
  EXPECT_EQ(tracker.drone_boxes(), 52 + 20 + 4 + 5);
  EXPECT_EQ(tracker.rejected_boxes(), 5);

  ClipTrackResult clip;
  clip.clip = "synthetic", clip.cls = "DRONE", clip.distance_bin = "MEDIUM";
  clip.fps = kFps;
  clip.frames = 60;
  clip.duration_s = 2.0;
  clip.first_label_frame = 6;
  clip.tracks = tracker.tracks();
  ASSERT_EQ(clip.tracks.size(), 2u);
  EXPECT_EQ(clip.tracks[0].track_id, 1);
  EXPECT_EQ(clip.tracks[0].confirmed_frame, 10);
  EXPECT_EQ(clip.tracks[0].hits, 50);
  EXPECT_EQ(clip.tracks[0].hits_on_target, 50);
  EXPECT_EQ(clip.tracks[1].track_id, 2);
  EXPECT_EQ(clip.tracks[1].confirmed_frame, 22);
  EXPECT_EQ(clip.tracks[1].hits, 18);
  EXPECT_EQ(clip.tracks[1].hits_on_target, 0);
  EXPECT_EQ(clip.tracks[1].last_frame, 59);  // still coasting: deleted only 1 s after its last hit (frame 39)

  score_clip(clip, TrackScoringOptions{});
  EXPECT_TRUE(clip.tracks[0].on_target);
  EXPECT_FALSE(clip.tracks[1].on_target);
  EXPECT_EQ(clip.false_tracks, 1);
  EXPECT_EQ(clip.drone_tracks, 1);
  EXPECT_TRUE(clip.drone_confirmed);
  EXPECT_NEAR(clip.time_to_confirm_s, 4.0 / 30.0, 1e-12);
}

TEST(ClipTracker, TimeComesFromTheFrameIndexNotTheCallCount) {
  // Every second frame (frame_step 2): hits at frames 0, 2, 4 confirm at frame 4 = 0.133 s, not at the third call's
  // 2 / 30 s.
  ClipTracker tracker(three_of_five(), nominal_pinhole(640, 512, 24.0), kFps);
  for (int f = 0; f <= 10; f += 2) tracker.add_frame(f, {box(200, 150, 20, 16)}, {cv::Rect2d(185, 140, 30, 20)});
  ClipTrackResult clip;
  clip.cls = "DRONE";
  clip.fps = kFps;
  clip.first_label_frame = 0;
  clip.tracks = tracker.tracks();
  score_clip(clip, TrackScoringOptions{});
  ASSERT_EQ(clip.tracks.size(), 1u);
  EXPECT_EQ(clip.tracks[0].confirmed_frame, 4);
  EXPECT_NEAR(clip.time_to_confirm_s, 4.0 / 30.0, 1e-12);
  EXPECT_THROW(tracker.add_frame(10, {}, {}), std::invalid_argument);  // not after the previous frame
  EXPECT_THROW(ClipTracker(localizer::LocalizerOptions{}, nominal_pinhole(640, 512, 24.0), 0.0), std::invalid_argument);
}

TEST(ScoreClip, MostOfTheConfirmedLifeDecidesAndTheFirstOnTargetTrackTimesTheClip) {
  ClipTrackResult clip;
  clip.cls = "DRONE";
  clip.fps = 30;
  clip.first_label_frame = 30;
  TrackRecord half{1, 15, 60, 10, 5, false};    // exactly half on the drone: not "most": false
  TrackRecord most{2, 45, 90, 10, 6, false};    // 6 of 10: on the drone, confirmed 15 frames after the first label
  TrackRecord later{3, 75, 90, 10, 10, false};  // on the drone too, but later
  TrackRecord none{4, 80, 90, 0, 0, false};     // confirmed, never hit again: false
  clip.tracks = {half, most, later, none};
  score_clip(clip, TrackScoringOptions{});
  EXPECT_FALSE(clip.tracks[0].on_target);
  EXPECT_TRUE(clip.tracks[1].on_target);
  EXPECT_TRUE(clip.tracks[2].on_target);
  EXPECT_FALSE(clip.tracks[3].on_target);
  EXPECT_EQ(clip.false_tracks, 2);
  EXPECT_EQ(clip.drone_tracks, 2);  // the drone's track broken once
  EXPECT_TRUE(clip.drone_confirmed);
  EXPECT_NEAR(clip.time_to_confirm_s, 0.5, 1e-12);
  // A track on the drone confirmed before the first label counts as confirmed at once.
  clip.tracks = {TrackRecord{1, 10, 90, 10, 10, false}};
  score_clip(clip, TrackScoringOptions{});
  EXPECT_EQ(clip.time_to_confirm_s, 0.0);
  // None on the drone.
  clip.tracks = {half};
  score_clip(clip, TrackScoringOptions{});
  EXPECT_FALSE(clip.drone_confirmed);
  EXPECT_EQ(clip.time_to_confirm_s, -1.0);
}

ClipTrackResult scored(const std::string& name, const std::string& cls, const std::string& bin, double duration_s,
                       int false_tracks, double time_to_confirm_s) {
  ClipTrackResult c;
  c.clip = name, c.cls = cls, c.distance_bin = bin;
  c.fps = 30;
  c.duration_s = duration_s;
  c.frames = static_cast<int>(duration_s * 30);
  c.false_tracks = false_tracks;
  c.drone_confirmed = time_to_confirm_s >= 0;
  c.time_to_confirm_s = time_to_confirm_s;
  return c;
}

TEST(SequenceEvalResult, GroupsGiveTheHandComputedRatesAndTargets) {
  SequenceEvalResult r;
  r.split = "val";
  r.clips = {scored("V_DRONE_001", "DRONE", "CLOSE", 360, 0, 0.5),         // 0.1 h
             scored("V_DRONE_002", "DRONE", "CLOSE", 360, 1, 1.5),         // 0.1 h, one false track, late
             scored("V_DRONE_003", "DRONE", "DISTANT", 360, 0, -1),        // never confirmed
             scored("V_BIRD_001", "BIRD", "MEDIUM", 1800, 1, -1),          // 0.5 h
             scored("V_AIRPLANE_001", "AIRPLANE", "CLOSE", 1800, 0, -1)};  // 0.5 h
  ClipTrackResult skipped = scored("V_HELICOPTER_001", "HELICOPTER", "CLOSE", 0, 0, -1);
  skipped.skipped = "videos/V_HELICOPTER_001.mp4: cannot open the video";
  r.clips.push_back(skipped);
  EXPECT_EQ(r.skipped(), 1);
  const std::vector<TrackGroupSummary> g = r.groups();
  ASSERT_EQ(g.size(), 6u);  // DRONE CLOSE, DRONE DISTANT, DRONE, AIRPLANE, BIRD, distractors (no helicopter counted)
  EXPECT_EQ(g[0].name, "DRONE CLOSE");
  EXPECT_EQ(g[0].clips, 2);
  EXPECT_NEAR(g[0].hours, 0.2, 1e-12);
  EXPECT_EQ(g[0].false_tracks, 1);
  EXPECT_NEAR(g[0].false_per_hour, 5.0, 1e-9);
  EXPECT_EQ(g[0].confirmed, 2);
  EXPECT_EQ(g[0].confirmed_within, 1);
  EXPECT_NEAR(g[0].median_time_to_confirm_s, 1.0, 1e-12);  // (0.5 + 1.5) / 2
  EXPECT_EQ(g[1].name, "DRONE DISTANT");
  EXPECT_EQ(g[1].confirmed, 0);
  EXPECT_EQ(g[1].median_time_to_confirm_s, -1.0);
  EXPECT_EQ(g[2].name, "DRONE");
  EXPECT_EQ(g[2].clips, 3);
  EXPECT_NEAR(g[2].false_per_hour, 1.0 / 0.3, 1e-9);
  EXPECT_EQ(g[2].confirmed_within, 1);
  EXPECT_EQ(g[3].name, "AIRPLANE");
  // Poisson 95 % upper bounds: 0 events: -ln 0.05 = 2.9957; 1 event: 4.7439 (chi-square 9.4877 / 2).
  EXPECT_NEAR(g[3].false_per_hour_upper95, 2.995732 / 0.5, 1e-4);
  EXPECT_EQ(g[4].name, "BIRD");
  EXPECT_EQ(g[5].name, "distractors");
  EXPECT_EQ(g[5].clips, 2);
  EXPECT_NEAR(g[5].hours, 1.0, 1e-12);
  EXPECT_EQ(g[5].false_tracks, 1);
  EXPECT_NEAR(g[5].false_per_hour, 1.0, 1e-12);
  EXPECT_NEAR(g[5].false_per_hour_upper95, 4.743865, 1e-4);
  const std::string report = r.report();
  EXPECT_NE(report.find("target <= 1 false track per hour of distractor video: 1.0 per hour (1 in 1.000 h): met"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("target >= 95 % of drone clips confirmed within 1 s: 33.3 % (1 of 3): not met"),
            std::string::npos)
      << report;
  EXPECT_NE(report.find("V_HELICOPTER_001: videos/V_HELICOPTER_001.mp4: cannot open the video"), std::string::npos)
      << report;
  EXPECT_NE(report.find("V_DRONE_003 (DISTANT): never confirmed"), std::string::npos) << report;
  const nlohmann::json json = nlohmann::json::parse(r.json());
  const nlohmann::json& distractors = json.at("groups").at(5);
  EXPECT_EQ(distractors["name"], "distractors") << json;
  EXPECT_EQ(distractors["drone"], false);
  EXPECT_EQ(distractors["clips"], 2);
  EXPECT_NEAR(distractors["hours"].get<double>(), 1.0, 1e-12);
  EXPECT_EQ(distractors["false_tracks"], 1);
  EXPECT_NEAR(distractors["false_tracks_per_hour"].get<double>(), 1.0, 1e-12);
  EXPECT_FALSE(distractors.contains("median_time_to_confirm_s"));  // drone groups only
  bool never_confirmed = false, skipped_listed = false;
  for (const nlohmann::json& g : json["groups"])
    never_confirmed |= g.at("drone").get<bool>() && g.at("median_time_to_confirm_s").is_null();
  for (const nlohmann::json& c : json["clips"])
    skipped_listed |= c["skipped"] == "videos/V_HELICOPTER_001.mp4: cannot open the video";
  EXPECT_TRUE(never_confirmed) << json;
  EXPECT_TRUE(skipped_listed) << json;
}

// ---- end to end on generated videos, with a detector that finds the bright square ----

/// The bounding box of the pixels brighter than 128, as a class-0 detection (none when there is none).
std::vector<detector::Box> bright_square(const cv::Mat& bgr) {
  cv::Mat grey, mask;
  cv::cvtColor(bgr, grey, cv::COLOR_BGR2GRAY);
  cv::threshold(grey, mask, 128, 255, cv::THRESH_BINARY);
  std::vector<cv::Point> on;
  cv::findNonZero(mask, on);
  if (on.empty()) return {};
  const cv::Rect r = cv::boundingRect(on);
  return {box(r.x + 0.5f * r.width, r.y + 0.5f * r.height, static_cast<float>(r.width), static_cast<float>(r.height))};
}

/// Writes `frames` frames of 160x128 at 30 fps with a white 8x8 square at (40, 30); false when this OpenCV cannot
/// write MPEG-4.
bool write_video(const std::string& path, int frames) {
  cv::VideoWriter w(path, cv::VideoWriter::fourcc('m', 'p', '4', 'v'), kFps, cv::Size(160, 128));
  if (!w.isOpened()) return false;
  for (int f = 0; f < frames; ++f) {
    cv::Mat img(128, 160, CV_8UC3, cv::Scalar(0, 0, 0));
    cv::rectangle(img, cv::Rect(40, 30, 8, 8), cv::Scalar(255, 255, 255), cv::FILLED);
    w.write(img);
  }
  return true;
}

/// Every frame of `frames` labelled with one `cls` box around the square (MATLAB pixels: +0.5).
void write_labels(const std::string& path, const std::string& cls, int frames) {
  std::ofstream f(path);
  f << "frame,class,x,y,w,h\n";
  for (int k = 0; k < frames; ++k) f << k << "," << cls << ",36.50,26.50,16.00,16.00\n";
}

/// A Halmstad-like folder (videos/, labels/) and an imported folder (splits.csv, data.yaml): V_DRONE_001 and V_BIRD_001
/// in val (40 frames each), V_DRONE_002 in train (no video: never read).
struct Fixture {
  testing::TempDir dir;
  std::string root = dir.file("halmstad"), data = dir.file("data");
  bool ok = false;
  Fixture() {
    fs::create_directories(root + "/videos");
    fs::create_directories(root + "/labels");
    fs::create_directories(data);
    ok = write_video(root + "/videos/V_DRONE_001.mp4", 40) && write_video(root + "/videos/V_BIRD_001.mp4", 40);
    write_labels(root + "/labels/V_DRONE_001.csv", "DRONE", 40);
    write_labels(root + "/labels/V_BIRD_001.csv", "BIRD", 40);
    std::ofstream(data + "/splits.csv") << "clip,class,distance_bin,split,images\n"
                                           "V_BIRD_001,BIRD,CLOSE,val,4\n"
                                           "V_DRONE_001,DRONE,MEDIUM,val,4\n"
                                           "V_DRONE_002,DRONE,MEDIUM,train,4\n";
    std::ofstream(data + "/data.yaml") << "path: .\ntrain: images/train\nval: images/val\nnames: [drone]\n";
  }
  SequenceEvalOptions options() const {
    SequenceEvalOptions o;
    o.data = data;
    o.halmstad_root = root;
    return o;
  }
};

#define REQUIRE_VIDEO(fx) \
  if (!(fx).ok) GTEST_SKIP() << "this OpenCV cannot write MPEG-4 video (VideoWriter mp4v): no generated clips"

TEST(RunSequenceEval, GeneratedClipsGiveOneDroneTrackAndOneFalseTrack) {
  Fixture fx;
  REQUIRE_VIDEO(fx);
  std::vector<std::string> log;
  const SequenceEvalResult r =
      run_sequence_eval(fx.options(), bright_square, [&](const std::string& l) { log.push_back(l); });
  ASSERT_EQ(r.clips.size(), 2u);
  EXPECT_EQ(log.size(), 2u);
  EXPECT_NEAR(r.focal_px, 80.0 / std::tan(12.0 * 3.14159265358979323846 / 180.0), 1e-9);
  const ClipTrackResult& bird = r.clips[0];
  const ClipTrackResult& drone = r.clips[1];
  EXPECT_EQ(bird.clip, "V_BIRD_001");
  EXPECT_EQ(drone.clip, "V_DRONE_001");
  for (const ClipTrackResult* c : {&bird, &drone}) {
    EXPECT_TRUE(c->skipped.empty()) << c->skipped;
    EXPECT_NEAR(c->fps, 30.0, 1e-3);
    EXPECT_EQ(c->frames, 40);
    EXPECT_EQ(c->frames_tracked, 40);
    EXPECT_EQ(c->drone_boxes, 40);
    EXPECT_NEAR(c->duration_s, 40.0 / 30.0, 1e-3);
    ASSERT_EQ(c->tracks.size(), 1u);
    EXPECT_EQ(c->tracks[0].confirmed_frame, 9);  // the tenth hit (the defaults: 10 of 15, confidence 0.9 >= 0.4)
    EXPECT_EQ(c->tracks[0].hits, 31);            // frames 9..39
  }
  // The bird's labels are not drone boxes: its one track is false; the drone's is on the drone.
  EXPECT_EQ(bird.first_label_frame, -1);
  EXPECT_EQ(bird.false_tracks, 1);
  EXPECT_EQ(drone.first_label_frame, 0);
  EXPECT_EQ(drone.false_tracks, 0);
  EXPECT_TRUE(drone.drone_confirmed);
  EXPECT_NEAR(drone.time_to_confirm_s, 9.0 / 30.0, 1e-3);
  const std::vector<TrackGroupSummary> g = r.groups();
  ASSERT_EQ(g.size(), 4u);  // DRONE MEDIUM, DRONE, BIRD, distractors
  EXPECT_EQ(g[3].name, "distractors");
  EXPECT_EQ(g[3].false_tracks, 1);
  EXPECT_NEAR(g[3].false_per_hour, 3600.0 / (40.0 / 30.0), 0.1);  // 1 in 1.33 s of video: 2700 per hour

  // Every 4th frame: the tracker sees frames 0, 4, ..., 36 and confirms at the tenth, frame 36; the video time is
  // unchanged.
  SequenceEvalOptions o = fx.options();
  o.frame_step = 4;
  o.clips = {"V_DRONE_001"};
  const SequenceEvalResult every4 = run_sequence_eval(o, bright_square);
  ASSERT_EQ(every4.clips.size(), 1u);
  EXPECT_EQ(every4.clips[0].frames, 40);
  EXPECT_EQ(every4.clips[0].frames_tracked, 10);
  EXPECT_NEAR(every4.clips[0].time_to_confirm_s, 36.0 / 30.0, 1e-3);

  // The first 0.5 s only (frames 0..14 of 30 fps): the detector sees 15 frames, the track is confirmed at the tenth
  // as over the whole clip, and the clip's duration is the part tracked.
  o = fx.options();
  o.max_seconds = 0.5;
  o.boxes_cache = fx.dir.file("boxes_limited");  // not written: a cache file holds a whole clip
  int calls = 0;
  const FrameDetector counted = [&](const cv::Mat& bgr) {
    ++calls;
    return bright_square(bgr);
  };
  const SequenceEvalResult first = run_sequence_eval(o, counted);
  EXPECT_EQ(calls, 30);  // 15 frames of each clip
  ASSERT_EQ(first.clips.size(), 2u);
  for (const ClipTrackResult& c : first.clips) {
    EXPECT_EQ(c.frames, 15) << c.clip;
    EXPECT_EQ(c.frames_tracked, 15) << c.clip;
    EXPECT_NEAR(c.duration_s, 0.5, 1e-3) << c.clip;
    ASSERT_EQ(c.tracks.size(), 1u) << c.clip;
    EXPECT_EQ(c.tracks[0].confirmed_frame, 9) << c.clip;
    EXPECT_EQ(c.tracks[0].hits, 6) << c.clip;  // frames 9..14
  }
  EXPECT_NEAR(first.clips[1].time_to_confirm_s, 9.0 / 30.0, 1e-3);
  EXPECT_NE(first.report().find("every frame of each clip's first 0.5 s"), std::string::npos) << first.report();
  EXPECT_EQ(nlohmann::json::parse(first.json())["max_seconds"], 0.5);
  EXPECT_TRUE(fs::is_empty(o.boxes_cache));

  // The same input twice gives the same JSON (deterministic).
  EXPECT_EQ(run_sequence_eval(fx.options(), bright_square).json(), r.json());
}

TEST(RunSequenceEval, UnreadableAndEmptyVideosAreSkippedAndNamed) {
  Fixture fx;
  REQUIRE_VIDEO(fx);
  std::ofstream(fx.root + "/videos/V_BIRD_001.mp4", std::ios::trunc) << "not a video";
  std::ofstream(fx.root + "/videos/V_DRONE_001.mp4", std::ios::trunc);  // empty
  const SequenceEvalResult r = run_sequence_eval(fx.options(), bright_square);
  ASSERT_EQ(r.clips.size(), 2u);
  EXPECT_EQ(r.skipped(), 2);
  for (const ClipTrackResult& c : r.clips) {
    EXPECT_NE(c.skipped.find(fx.root + "/videos/" + c.clip + ".mp4"), std::string::npos) << c.skipped;
    EXPECT_TRUE(c.tracks.empty());
  }
  EXPECT_TRUE(r.groups().empty());
  EXPECT_NE(r.report().find("skipped clips:\n    V_BIRD_001: " + fx.root + "/videos/V_BIRD_001.mp4"), std::string::npos)
      << r.report();
  // A missing video too.
  fs::remove(fx.root + "/videos/V_DRONE_001.mp4");
  EXPECT_EQ(run_sequence_eval(fx.options(), bright_square).skipped(), 2);
}

TEST(RunSequenceEval, BadInputIsOneErrorNamingTheFile) {
  Fixture fx;
  // No such folder; a folder without splits.csv.
  SequenceEvalOptions o = fx.options();
  o.data = fx.dir.file("nothing-here");
  std::string e = error_of([&] { run_sequence_eval(o, bright_square); });
  EXPECT_NE(e.find(fx.dir.file("nothing-here") + ": no such folder or file"), std::string::npos) << e;
  o.data = fx.root;
  e = error_of([&] { run_sequence_eval(o, bright_square); });
  EXPECT_NE(e.find(fx.root + "/splits.csv: no splits.csv"), std::string::npos) << e;
  // data.yaml names its folder.
  o.data = fx.data + "/data.yaml";
  o.split = "test";
  e = error_of([&] { run_sequence_eval(o, bright_square); });
  EXPECT_NE(e.find(fx.data + "/splits.csv: no clip is in split 'test'"), std::string::npos) << e;
  // A clip not in the split.
  o = fx.options();
  o.clips = {"V_DRONE_002"};
  e = error_of([&] { run_sequence_eval(o, bright_square); });
  EXPECT_NE(e.find("clip 'V_DRONE_002' is not in split 'val'"), std::string::npos) << e;
  // A bad splits.csv line.
  std::ofstream(fx.data + "/splits.csv") << "clip,class,distance_bin,split,images\nV_KITE_001,KITE,CLOSE,val,3\n";
  e = error_of([&] { run_sequence_eval(fx.options(), bright_square); });
  EXPECT_NE(e.find(fx.data + "/splits.csv:2: field class = 'KITE'"), std::string::npos) << e;
  std::ofstream(fx.data + "/splits.csv") << "clip,class,distance_bin,split,images\nV_DRONE_001,DRONE,MEDIUM,val,4\n";
  // A label with an unknown class, before any frame is read.
  std::ofstream(fx.root + "/labels/V_DRONE_001.csv") << "frame,class,x,y,w,h\n0,DRONE,1,1,5,5\n1,KITE,1,1,5,5\n";
  e = error_of([&] { run_sequence_eval(fx.options(), bright_square); });
  EXPECT_NE(e.find(fx.root + "/labels/V_DRONE_001.csv:3: field class = 'KITE': expected DRONE, AIRPLANE, BIRD or "
                             "HELICOPTER"),
            std::string::npos)
      << e;
  // A missing label file.
  fs::remove(fx.root + "/labels/V_DRONE_001.csv");
  e = error_of([&] { run_sequence_eval(fx.options(), bright_square); });
  EXPECT_NE(e.find(fx.root + "/labels/V_DRONE_001.csv: cannot read the label file"), std::string::npos) << e;
  // Not a Halmstad folder.
  o = fx.options();
  o.halmstad_root = fx.dir.file("elsewhere");
  e = error_of([&] { run_sequence_eval(o, bright_square); });
  EXPECT_NE(e.find(fx.dir.file("elsewhere") + ": not the Halmstad dataset folder"), std::string::npos) << e;
  // A localizer config with a bad key: the common loader names the file and the key.
  std::ofstream(fx.dir.file("loc.yaml")) << "tracker:\n  birth_hits: 0\n  no_such_key: 1\n";
  o = fx.options();
  o.localizer_config = fx.dir.file("loc.yaml");
  EXPECT_THROW(run_sequence_eval(o, bright_square), common::ConfigError);
  e = error_of([&] { run_sequence_eval(o, bright_square); });
  EXPECT_NE(e.find("loc.yaml"), std::string::npos) << e;
  EXPECT_NE(e.find("tracker.birth_hits"), std::string::npos) << e;
  EXPECT_NE(e.find("tracker.no_such_key"), std::string::npos) << e;
}

TEST(RunSequenceEval, LocalizerConfigChangesTheBirthRule) {
  Fixture fx;
  REQUIRE_VIDEO(fx);
  // M = 5 (of N = 15): the drone is confirmed at its fifth hit, frame 4.
  std::ofstream(fx.dir.file("loc.yaml")) << "tracker:\n  birth_hits: 5\n";
  SequenceEvalOptions o = fx.options();
  o.localizer_config = fx.dir.file("loc.yaml");
  o.clips = {"V_DRONE_001"};
  const SequenceEvalResult r = run_sequence_eval(o, bright_square);
  ASSERT_EQ(r.clips.size(), 1u);
  EXPECT_NEAR(r.clips[0].time_to_confirm_s, 4.0 / 30.0, 1e-3);
  // A confidence bar above the boxes' 0.9: never confirmed.
  std::ofstream(fx.dir.file("loc.yaml"), std::ios::trunc) << "tracker:\n  confirm_min_confidence: 0.95\n";
  const SequenceEvalResult barred = run_sequence_eval(o, bright_square);
  ASSERT_EQ(barred.clips.size(), 1u);
  EXPECT_TRUE(barred.clips[0].tracks.empty());
  EXPECT_FALSE(barred.clips[0].drone_confirmed);
}

TEST(RunSequenceEval, BoxesCacheGivesTheSameResultWithoutTheDetectorOrTheVideo) {
  Fixture fx;
  REQUIRE_VIDEO(fx);
  SequenceEvalOptions o = fx.options();
  o.boxes_cache = fx.dir.file("boxes");
  int calls = 0;
  const FrameDetector counted = [&](const cv::Mat& bgr) {
    ++calls;
    std::vector<detector::Box> b = bright_square(bgr);
    // Scores and a second class that must come back exactly.
    if (!b.empty()) b[0].confidence = b[0].drone_score = 0.123456789f + 1e-3f * static_cast<float>(calls % 7);
    b.push_back(box(100.25f, 90.5f, 3.0f, 2.0f, 2));
    return b;
  };
  const SequenceEvalResult live = run_sequence_eval(o, counted);
  EXPECT_EQ(calls, 80);
  ASSERT_TRUE(fs::exists(o.boxes_cache + "/V_DRONE_001.boxes"));
  // The videos are gone: the cache alone gives the same result, and the detector is not called.
  fs::remove(fx.root + "/videos/V_DRONE_001.mp4");
  fs::remove(fx.root + "/videos/V_BIRD_001.mp4");
  const SequenceEvalResult cached = run_sequence_eval(o, counted);
  EXPECT_EQ(calls, 80);
  EXPECT_EQ(cached.json(), live.json());
  EXPECT_EQ(cached.clips[1].other_class_boxes, 40);
  const ClipBoxes b = read_clip_boxes(o.boxes_cache + "/V_DRONE_001.boxes");
  EXPECT_EQ(b.settings, "custom detector");
  EXPECT_EQ(b.frames, 40);
  EXPECT_EQ(b.width, 160);
  EXPECT_EQ(b.height, 128);
  ASSERT_EQ(b.boxes.size(), 40u);
  EXPECT_FLOAT_EQ(b.boxes.at(0)[1].cx, 100.25f);

  // A time limit reads the cached whole clips up to it (the detector is not called).
  SequenceEvalOptions limited = o;
  limited.max_seconds = 0.5;
  const SequenceEvalResult part = run_sequence_eval(limited, counted);
  EXPECT_EQ(calls, 80);
  ASSERT_EQ(part.clips.size(), 2u);
  EXPECT_EQ(part.clips[1].frames, 15);
  EXPECT_EQ(part.clips[1].frames_tracked, 15);
  EXPECT_EQ(part.clips[1].drone_boxes, 15);
  EXPECT_EQ(part.clips[1].other_class_boxes, 15);

  // Other settings: one error naming the file and both settings.
  o.frame_step = 2;
  std::string e = error_of([&] { run_sequence_eval(o, counted); });
  EXPECT_NE(e.find("V_BIRD_001.boxes: made with frame_step 1, this run 2"), std::string::npos) << e;
  const std::string path = o.boxes_cache + "/V_BIRD_001.boxes";
  ClipBoxes other = read_clip_boxes(path);
  other.settings = "cfg=x";
  write_clip_boxes(path, other);
  o.frame_step = 1;
  e = error_of([&] { run_sequence_eval(o, counted); });
  EXPECT_NE(e.find(path + ": made with other detection settings: the file has 'cfg=x', this run 'custom detector'"),
            std::string::npos)
      << e;
  // A damaged file names its line.
  std::ofstream(path, std::ios::app) << "3 0 0.5 0.5 1 1 -4 4 0\n";
  e = error_of([&] { read_clip_boxes(path); });
  EXPECT_NE(e.find(path + ":"), std::string::npos) << e;
  EXPECT_NE(e.find("a box needs"), std::string::npos) << e;
  std::ofstream(path, std::ios::trunc) << "something else\n";
  e = error_of([&] { read_clip_boxes(path); });
  EXPECT_NE(e.find(path + ":1: not a boxes cache file"), std::string::npos) << e;
  std::ofstream(path, std::ios::trunc) << "# wingman val --sequences boxes v1\nsettings s\nvideo 30 10 160 128 1\n12 0 "
                                          "0.5 0.5 1 1 2 2 0\n";
  e = error_of([&] { read_clip_boxes(path); });
  EXPECT_NE(e.find(path + ":4: frame 12: not a tracked frame of 10"), std::string::npos) << e;
  // A frame count that would loop for ever, and an infinite box, are named too.
  std::ofstream(path, std::ios::trunc)
      << "# wingman val --sequences boxes v1\nsettings s\nvideo 30 2000000000 160 128 1\n";
  e = error_of([&] { read_clip_boxes(path); });
  EXPECT_NE(e.find(path + ":3: video 30 2000000000 160 128 1: needs fps in (0, 1000], frames in [0, 10000000]"),
            std::string::npos)
      << e;
  std::ofstream(path, std::ios::trunc) << "# wingman val --sequences boxes v1\nsettings s\nvideo 30 10 160 128 1\n"
                                          "2 0 0.5 0.5 1 1 1e39 2 0\n";
  e = error_of([&] { read_clip_boxes(path); });
  EXPECT_NE(e.find(path + ":4:"), std::string::npos) << e;
}

// ---- the `wingman` binary ----

testing::RunResult wingman_sequences(const std::vector<std::string>& args, int timeout_s = 120) {
  std::vector<std::string> argv = {testing::bin_path("wingman")};
  argv.insert(argv.end(), args.begin(), args.end());
  return testing::run(argv, std::chrono::seconds(timeout_s));
}

TEST(WingmanValSequences, MissingSplitsAndPredictionsAreOneErrorLine) {
  Fixture fx;
  const auto missing = wingman_sequences({"val", "--sequences", "--data", fx.root, "--halmstad-root", fx.root});
  EXPECT_EQ(missing.exit_code, 1);
  EXPECT_EQ(missing.err.rfind("wingman val: error: " + fx.root + "/splits.csv: no splits.csv", 0), 0u) << missing.err;
  EXPECT_EQ(missing.err.find("wingman val:", 1), std::string::npos) << missing.err;
  const auto pred = wingman_sequences(
      {"val", "--sequences", "--data", fx.data, "--halmstad-root", fx.root, "--predictions", fx.dir.path()});
  EXPECT_EQ(pred.exit_code, 2);
  EXPECT_NE(pred.err.find("--predictions: --sequences runs the detector on every frame"), std::string::npos)
      << pred.err;
  const auto bad =
      wingman_sequences({"val", "--sequences", "--data", fx.data, "--halmstad-root", fx.root, "--hfov-deg", "0"});
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("hfov_deg = 0: must be in (0, 180)"), std::string::npos) << bad.err;
}

TEST(WingmanValSequences, JsonFileBesideTheTable) {
  // `--json FILE` prints the table and writes the JSON, in both modes; `--json` alone prints the JSON instead.
  testing::TempDir dir;
  write_hand_case(dir);
  const auto images = wingman_sequences(
      {"val", "--data", dir.file("data.yaml"), "--predictions", dir.file("pred"), "--json", dir.file("val.json")});
  ASSERT_EQ(images.exit_code, 0) << images.err;
  EXPECT_NE(images.out.find("match centre in truth box"), std::string::npos) << images.out;
  std::ifstream in(dir.file("val.json"));
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(nlohmann::json::parse(json).at("images"), 3) << json;

  Fixture fx;
  REQUIRE_VIDEO(fx);
  // The shipped model on the generated 160x128 clips (whatever it finds there: the table and the file are checked).
  const auto seq = wingman_sequences(
      {"val", "--sequences", "--data", fx.data, "--halmstad-root", fx.root, "--json", fx.dir.file("seq.json")});
  ASSERT_EQ(seq.exit_code, 0) << seq.err;
  EXPECT_EQ(seq.out.rfind("track-level metrics: 2 clips of split 'val' (0 skipped), every frame", 0), 0u) << seq.out;
  EXPECT_NE(seq.out.find("target <= 1 false track per hour of distractor video"), std::string::npos) << seq.out;
  std::ifstream seq_in(fx.dir.file("seq.json"));
  const std::string seq_json((std::istreambuf_iterator<char>(seq_in)), std::istreambuf_iterator<char>());
  const nlohmann::json seq_doc = nlohmann::json::parse(seq_json);
  EXPECT_EQ(seq_doc.at("split"), "val") << seq_json;
  EXPECT_EQ(seq_doc.at("hfov_deg"), 24.0) << seq_json;
  EXPECT_EQ(seq_json.rfind("{\n  \"split\": \"val\",\n  \"hfov_deg\": 24.0,", 0), 0u) << seq_json;  // keys in order
  const auto stdout_json = wingman_sequences(
      {"val", "--sequences", "--data", fx.data, "--halmstad-root", fx.root, "--clips", "V_BIRD_001", "--json"});
  ASSERT_EQ(stdout_json.exit_code, 0) << stdout_json.err;
  EXPECT_EQ(nlohmann::json::parse(stdout_json.out).at("split"), "val") << stdout_json.out;
}

// ---- one real clip (skipped without ../shared) ----

std::string halmstad_root() {
  const char* env = std::getenv("WINGMAN_SOURCE_DIR");
  const fs::path root = fs::path(env ? env : ".") / ".." / "shared" / "datasets" / "halmstad";
  return fs::is_regular_file(root / "clips.csv") ? root.string() : "";
}

TEST(RunSequenceEval, RealDroneClipWithTheShippedModel) {
  const std::string root = halmstad_root();
  if (root.empty())
    GTEST_SKIP() << "../shared/datasets/halmstad is absent (read-only shared data, not part of the repository): the "
                    "real clip is not tracked here";
  testing::TempDir dir;
  // V_DRONE_003 (MEDIUM; one of the seed-1 val clips): 313 frames at 30 fps, a drone box in every frame.
  std::ofstream(dir.file("splits.csv")) << "clip,class,distance_bin,split,images\nV_DRONE_003,DRONE,MEDIUM,val,32\n";
  SequenceEvalOptions o;
  o.data = dir.path();
  o.halmstad_root = root;
  const SequenceEvalResult r = run_sequence_eval(o);
  ASSERT_EQ(r.clips.size(), 1u);
  const ClipTrackResult& c = r.clips[0];
  ASSERT_TRUE(c.skipped.empty()) << c.skipped;
  EXPECT_EQ(c.frames, 313);
  EXPECT_NEAR(c.fps, 30.0, 1e-6);
  EXPECT_EQ(c.first_label_frame, 0);
  // The shipped model (2026-12-05) finds this drone in nearly every frame: it is confirmed as one track within 1 s,
  // and nothing else is.
  EXPECT_TRUE(c.drone_confirmed) << r.report();
  EXPECT_LE(c.time_to_confirm_s, 1.0) << r.report();
  EXPECT_EQ(c.false_tracks, 0) << r.report();
  EXPECT_EQ(r.motion.frames, 0);

  // With the motion cue: every frame goes through it (the first 2 lag_frames only fill its history), and the drone,
  // found by the single pass in nearly every frame, is confirmed as before with nothing else.
  o.motion.enabled = true;
  const SequenceEvalResult m = run_sequence_eval(o);
  ASSERT_EQ(m.clips.size(), 1u);
  EXPECT_EQ(m.motion.frames, 313);
  EXPECT_EQ(m.motion.restarts, 0) << m.report();
  EXPECT_EQ(m.motion.compared, 313 - 2 * o.motion.lag_frames) << m.report();
  EXPECT_TRUE(m.clips[0].drone_confirmed) << m.report();
  EXPECT_EQ(m.clips[0].false_tracks, 0) << m.report();
  EXPECT_NE(m.report().find("motion cue: "), std::string::npos);
  EXPECT_NE(m.json().find("\"motion\""), std::string::npos);
}

}  // namespace
}  // namespace wingman::training
