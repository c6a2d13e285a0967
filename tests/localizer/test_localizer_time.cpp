// SPDX-License-Identifier: MIT
// Localizer input times (issue 33, finding 3): one future-dated detections_t or own pose neither latches the
// input order nor blinds the localizer; a bad first message is forgotten within time.resync_after_s.
#include "wingman/localizer/localizer.hpp"

#include "test_constants.hpp"

#include <wingman/common/config.hpp>

#include <gtest/gtest.h>

#include <stdexcept>
#include <string>

namespace {

using wingman::geometry::CameraModel;
using wingman::localizer::Localizer;
using wingman::localizer::LocalizerOptions;
using wingman::localizer::LocalizerOutput;
using wingman::testing::kT0;

constexpr int64_t kS = 1000000;

CameraModel centred_camera() { return CameraModel::pinhole(1280, 720, 640, 640, 639.5, 359.5); }

wingman::own_pose_t pose_at(int64_t utime) {
  wingman::own_pose_t m{};
  m.utime = utime;
  m.frame = wingman::own_pose_t::FRAME_ENU;
  m.p_body_in_world[2] = 5.0;
  m.q_body_to_world[0] = 1.0;
  return m;
}

/// A detections message without boxes (ground truth: no box relation involved): what matters here is whether it
/// is accepted and finds an own pose.
wingman::detections_t detections_at(int64_t utime) {
  wingman::detections_t d{};
  d.utime = utime;
  d.camera_id = 0;
  d.image_width = 1280;
  d.image_height = 720;
  d.source = wingman::detections_t::SOURCE_GROUND_TRUTH;
  return d;
}

/// What a 3-second flight (own poses at 50 Hz, detections at 30 Hz with 40 ms latency) gave after the lie.
struct Result {
  int detections_after = 0;  ///< detections messages after the lie
  int dropped_after = 0;     ///< of those, thrown (dropped and counted by the process)
  int blind_after = 0;       ///< of those, accepted but without an own pose (camera frame only)
  int late_after = 0;        ///< dropped or blind more than time.resync_after_s + 0.1 s after the lie
  int lie_thrown = 0;        ///< the lie itself was refused
};

enum class Lie { kFutureDetections, kFutureOwnPose, kFirstMessageInTheFuture };

Result fly(Lie lie) {
  Localizer loc(LocalizerOptions{}, centred_camera());
  Result r;
  const int64_t lie_at = lie == Lie::kFirstMessageInTheFuture ? 0 : kS;
  auto send_lie = [&] {
    try {
      if (lie == Lie::kFutureOwnPose) {
        loc.on_own_pose(pose_at(kT0 + lie_at + 1000 * kS));
      } else {
        loc.on_detections(detections_at(kT0 + lie_at + 1000 * kS));
      }
    } catch (const std::invalid_argument&) {
      ++r.lie_thrown;
    }
  };
  if (lie == Lie::kFirstMessageInTheFuture) send_lie();
  int64_t next_detections = 0;
  for (int64_t t = 0; t <= 3 * kS; t += 20000) {
    if (t == lie_at && lie != Lie::kFirstMessageInTheFuture) send_lie();
    try {
      loc.on_own_pose(pose_at(kT0 + t));
    } catch (const std::invalid_argument&) {
    }
    while (next_detections + 40000 <= t) {  // the detections of images up to 40 ms ago
      const int64_t image = next_detections;
      next_detections += 33333;
      if (image < 0 || image <= lie_at) continue;
      ++r.detections_after;
      const bool late = image > lie_at + kS + 100000;
      try {
        const LocalizerOutput out = loc.on_detections(detections_at(kT0 + image));
        if (out.camera_frame_only) {
          ++r.blind_after;
          r.late_after += late;
        }
      } catch (const std::invalid_argument&) {
        ++r.dropped_after;
        r.late_after += late;
      }
    }
  }
  return r;
}

TEST(LocalizerTime, OneFutureDetectionsIsDroppedAndLaterOnesAreTaken) {
  const Result r = fly(Lie::kFutureDetections);
  EXPECT_EQ(r.lie_thrown, 1);
  EXPECT_GT(r.detections_after, 50);
  EXPECT_EQ(r.dropped_after, 0) << "of " << r.detections_after << ": the input order latched on the lie";
  EXPECT_EQ(r.blind_after, 0);
}

TEST(LocalizerTime, OneFutureOwnPoseIsDroppedAndDoesNotBlindTheLocalizer) {
  const Result r = fly(Lie::kFutureOwnPose);
  EXPECT_EQ(r.lie_thrown, 1);
  EXPECT_EQ(r.dropped_after, 0);
  EXPECT_EQ(r.blind_after, 0) << "of " << r.detections_after << ": no own pose found after the lie";
}

TEST(LocalizerTime, AResyncIsANoteForTheLogNamingWhatWasForgotten) {
  Localizer loc(LocalizerOptions{}, centred_camera());
  loc.on_own_pose(pose_at(kT0 + 1000 * kS));  // a first own pose from the future: the clock anchors on it
  EXPECT_TRUE(loc.take_notes().empty());
  int refused = 0;
  for (int64_t t = 0; t <= 2 * kS; t += 20000) {
    try {
      loc.on_own_pose(pose_at(kT0 + t));
    } catch (const std::invalid_argument&) {
      ++refused;
    }
  }
  EXPECT_GT(refused, 0);
  const std::vector<std::string> notes = loc.take_notes();
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("the own-pose buffer is emptied"), std::string::npos) << notes[0];
  EXPECT_TRUE(loc.take_notes().empty()) << "taken once";
}

TEST(LocalizerTime, AFutureFirstMessageIsForgottenWithinTheResyncTime) {
  const Result r = fly(Lie::kFirstMessageInTheFuture);
  EXPECT_EQ(r.lie_thrown, 0) << "the first message has nothing to be compared with";
  EXPECT_GT(r.dropped_after, 0) << "the real detections are refused until the resync";
  EXPECT_EQ(r.late_after, 0) << "of " << r.detections_after << " (dropped " << r.dropped_after << ", blind "
                             << r.blind_after << "): still refused after time.resync_after_s";
}

TEST(LocalizerTime, WhenTimeGoesBackForEveryInputTheLocalizerStartsAgainWithinTheResyncTime) {
  // A restarted source (a replayed log, a restarted simulator): own poses and detections both jump 100 s back. They
  // are refused for time.resync_after_s of their own time, then the clock re-anchors and the localizer works again:
  // detections find own poses and the tracker takes frames (a new tracker: the old tracks live in the old times).
  Localizer loc(LocalizerOptions{}, centred_camera());
  const int64_t back = -100 * kS;
  int refused = 0, blind_late = 0, taken_late = 0;
  int64_t next_detections = 0;
  for (int64_t t = 0; t <= 5 * kS; t += 20000) {
    const int64_t shift = t < 2 * kS ? 0 : back;
    try {
      loc.on_own_pose(pose_at(kT0 + shift + t));
    } catch (const std::invalid_argument&) {
      ++refused;
    }
    while (next_detections + 40000 <= t) {  // the detections of images up to 40 ms ago
      const int64_t image = next_detections;
      next_detections += 33333;
      const int64_t image_shift = image < 2 * kS ? 0 : back;
      const bool late = image > 3 * kS + 100000;  // after the jump (2 s) + time.resync_after_s (1 s) + 0.1 s
      try {
        const LocalizerOutput out = loc.on_detections(detections_at(kT0 + image_shift + image));
        if (late) out.camera_frame_only ? ++blind_late : ++taken_late;
      } catch (const std::invalid_argument&) {
        ++refused;
        if (late) ++blind_late;
      }
    }
  }
  EXPECT_GT(refused, 0) << "refused until the resync";
  EXPECT_EQ(blind_late, 0) << "still refused or without an own pose after time.resync_after_s (" << taken_late
                           << " taken)";
  EXPECT_GT(taken_late, 50);
  bool noted = false;
  for (const std::string& n : loc.take_notes())
    noted = noted || n.find("time went back with a resync of another input; the tracker restarts") != std::string::npos;
  EXPECT_TRUE(noted) << "the restart is a note for the log";
}

}  // namespace

namespace {

TEST(LocalizerTime, TheTimeKeysComeFromTheLocalizersConfiguration) {
  // time.max_ahead_s 5: a detections message 2 s ahead of the newest accepted time is taken; with the default 1 s it
  // is dropped.
  for (const double max_ahead_s : {1.0, 5.0}) {
    const auto o = wingman::common::load_options_from_string<LocalizerOptions>(
        "time: {max_ahead_s: " + std::to_string(max_ahead_s) + "}\n", "localizer.yaml");
    EXPECT_EQ(o.time.max_ahead_s, max_ahead_s);
    Localizer loc(o, centred_camera());
    loc.on_own_pose(pose_at(kT0));
    (void)loc.on_detections(detections_at(kT0));
    if (max_ahead_s < 2.0) {
      EXPECT_THROW(loc.on_detections(detections_at(kT0 + 2 * kS)), std::invalid_argument);
    } else {
      EXPECT_NO_THROW(loc.on_detections(detections_at(kT0 + 2 * kS)));
    }
  }
  // Bad values are named with their key, as every other key (issue 33, finding 6: .inf never gave a target).
  std::string all;
  try {
    (void)wingman::common::load_options_from_string<LocalizerOptions>(
        "time: {max_ahead_s: -1}\ntracker: {death_timeout_s: .inf}\n", "localizer.yaml");
  } catch (const std::exception& e) {
    all = e.what();
  }
  EXPECT_NE(all.find("time.max_ahead_s"), std::string::npos) << all;
  EXPECT_NE(all.find("tracker.death_timeout_s = inf: must be in (0, 3600] s"), std::string::npos) << all;
}

}  // namespace
