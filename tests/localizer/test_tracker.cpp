// SPDX-License-Identifier: MIT
// Tracker: options, frame order, M-of-N birth, death, ids, false-positive burst, crossing targets,
// accuracy (raw vs sliding window vs Kalman) and lag compensation on simulated detections.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <wingman/common/config.hpp>
#include <wingman/localizer/tracker.hpp>

#include "test_constants.hpp"

#include <Eigen/Cholesky>

#include <cmath>
#include <random>

namespace {

using wingman::localizer::Tracker;
using wingman::localizer::TrackerOptions;
using wingman::localizer::TrackerStats;
using wingman::localizer::TrackOutput;
using wingman::localizer::WorldMeasurement;
using wingman::testing::kT0;

constexpr int64_t kFrameUs = 100'000;  // 10 Hz detections

int64_t frame_utime(int k) { return kT0 + kFrameUs * k; }
double seconds(int64_t utime) { return static_cast<double>(utime - kT0) * 1e-6; }

WorldMeasurement meas(const Eigen::Vector3d& p, double sigma = 0.2, double confidence = 0.9) {
  WorldMeasurement m;
  m.p_target_in_world = p;
  m.cov_p_in_world = sigma * sigma * Eigen::Matrix3d::Identity();
  m.p_target_in_cam = p;
  m.range = p.norm();
  m.confidence = confidence;
  return m;
}

// Noisy world-frame detections as the sphere model gives them, seen from a camera at the origin:
// range error 5 % of range along the line of sight, 1 % across it.
class Detections {
 public:
  explicit Detections(unsigned seed) : rng_(seed) {}
  WorldMeasurement operator()(const Eigen::Vector3d& truth, double confidence = 0.9) {
    const double range = truth.norm();
    const Eigen::Vector3d u = truth / range;
    const double s_r = 0.05 * range, s_l = 0.01 * range;
    const Eigen::Matrix3d R =
        s_r * s_r * u * u.transpose() + s_l * s_l * (Eigen::Matrix3d::Identity() - u * u.transpose());
    const Eigen::Vector3d w(g_(rng_), g_(rng_), g_(rng_));
    WorldMeasurement m;
    m.p_target_in_world = truth + Eigen::LLT<Eigen::Matrix3d>(R).matrixL() * w;
    m.cov_p_in_world = R;
    m.range = m.p_target_in_world.norm();
    m.confidence = confidence;
    return m;
  }
  std::mt19937& rng() { return rng_; }

 private:
  std::mt19937 rng_;
  std::normal_distribution<double> g_{0, 1};
};

// The 3-of-5 birth rule without a confidence bar (the defaults before the Halmstad track-level operating point): the
// frame counts these tests compute by hand. The defaults have their own test.
TrackerOptions three_of_five() {
  TrackerOptions o;
  o.birth_hits = 3;
  o.birth_window = 5;
  o.confirm_min_confidence = 0.0;
  return o;
}

// A target on a horizontal circle of radius 10 m around (20, 0, 5) at constant speed (m/s).
Eigen::Vector3d circle(double t, double speed) {
  const double r = 10, a = speed * t / r;
  return Eigen::Vector3d(20 + r * std::cos(a), r * std::sin(a), 5);
}

TEST(TrackerOptions, DefaultsAreValidAndBadValuesAreNamed) {
  EXPECT_TRUE(TrackerOptions{}.validate().empty());
  TrackerOptions o;
  o.mode = "best";
  o.birth_hits = 4;
  o.birth_window = 3;
  o.gate_chi2 = 0;
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NE(p[0].find("tracker.mode = 'best'"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("tracker.gate_chi2"), std::string::npos) << p[1];
  EXPECT_NE(p[2].find("tracker.birth_window = 3"), std::string::npos) << p[2];
  EXPECT_THROW(Tracker{o}, std::invalid_argument);
  const auto y = wingman::common::load_options_from_string<TrackerOptions>(
      "tracker: {mode: sliding_window, window_size: 7}\n", "localizer.yaml");
  EXPECT_EQ(y.mode, "sliding_window");
  EXPECT_EQ(y.window_size, 7);
}

TEST(Tracker, TheDefaultsConfirmAtTheTenthHitOfFifteenFramesOnlyWithAMeanConfidenceOfAtLeast0p4) {
  const Eigen::Vector3d p(15, 2, 3);
  for (const double confidence : {0.45, 0.35}) {
    Tracker t;
    for (int k = 0; k < 9; ++k) t.update(frame_utime(k), {meas(p, 0.2, confidence)});
    EXPECT_TRUE(t.confirmed(frame_utime(8)).empty()) << confidence;
    t.update(frame_utime(9), {meas(p, 0.2, confidence)});  // the tenth hit
    EXPECT_EQ(t.confirmed(frame_utime(9)).size(), confidence >= 0.4 ? 1u : 0u) << confidence;
    EXPECT_EQ(t.num_tentative(), confidence >= 0.4 ? 0u : 1u) << confidence;
  }
}

TEST(Tracker, RefusesFramesThatAreNotLaterWithAReason) {
  Tracker t(three_of_five());
  std::string why;
  ASSERT_TRUE(t.update(frame_utime(5), {meas({10, 0, 0})}, &why));
  EXPECT_FALSE(t.update(frame_utime(5), {meas({10, 0, 0})}, &why));
  EXPECT_NE(why.find("not after the previous frame"), std::string::npos) << why;
  EXPECT_FALSE(t.update(frame_utime(4), {meas({10, 0, 0})}, &why));
  EXPECT_EQ(t.stats().frames, 1);
  EXPECT_EQ(t.stats().frames_rejected, 2);
  EXPECT_EQ(t.num_tentative(), 1u);  // the refused frames changed nothing
}

TEST(Tracker, ConfirmsAfterMHitsInNFramesAndIdsStartAtOne) {
  Tracker t(three_of_five());  // M = 3, N = 5
  const Eigen::Vector3d p(15, 2, 3);
  t.update(frame_utime(0), {meas(p)});
  t.update(frame_utime(1), {});
  t.update(frame_utime(2), {meas(p)});
  EXPECT_EQ(t.num_tentative(), 1u);
  EXPECT_TRUE(t.confirmed(frame_utime(2)).empty());
  t.update(frame_utime(3), {});
  t.update(frame_utime(4), {meas(p)});  // third hit in the fifth frame
  const auto out = t.confirmed(frame_utime(4));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].track_id, 1);
  EXPECT_EQ(t.num_tentative(), 0u);
  EXPECT_EQ(out[0].source_utime, frame_utime(4));
  EXPECT_NEAR(out[0].age_s, 0.4, 1e-12);
}

TEST(Tracker, DropsATentativeTrackThatCannotReachMHits) {
  Tracker t(three_of_five());
  const Eigen::Vector3d p(15, 2, 3);
  t.update(frame_utime(0), {meas(p)});
  t.update(frame_utime(1), {});
  t.update(frame_utime(2), {});
  t.update(frame_utime(3), {meas(p)});  // 2 hits in 4 frames: 3 still possible
  EXPECT_EQ(t.num_tentative(), 1u);
  t.update(frame_utime(4), {});  // 2 hits in 5 frames: dropped
  EXPECT_EQ(t.num_tentative(), 0u);
  EXPECT_EQ(t.stats().tentative_dropped, 1);
  EXPECT_TRUE(t.confirmed(frame_utime(4)).empty());
}

TEST(Tracker, ALowConfidenceDetectionContinuesATrackButStartsNone) {
  TrackerOptions o = three_of_five();
  o.birth_min_confidence = 0.5;
  o.birth_hits = 2;
  o.birth_window = 2;
  Tracker t(o);
  const Eigen::Vector3d p(15, 2, 3), q(-10, 4, 2);
  t.update(frame_utime(0), {meas(p, 0.2, 0.3)});  // below: no track
  EXPECT_EQ(t.num_tentative(), 0u);
  EXPECT_EQ(t.stats().births_refused, 1);
  t.update(frame_utime(1), {meas(p, 0.2, 0.6)});  // at or above: a tentative track
  EXPECT_EQ(t.num_tentative(), 1u);
  t.update(frame_utime(2), {meas(p, 0.2, 0.3), meas(q, 0.2, 0.3)});  // p's low box continues it; q's starts nothing
  ASSERT_EQ(t.confirmed(frame_utime(2)).size(), 1u);
  EXPECT_EQ(t.num_tentative(), 0u);
  EXPECT_EQ(t.stats().births_refused, 2);
  EXPECT_EQ(t.stats().births, 1);
}

TEST(Tracker, ATrackIsConfirmedOnlyOnceTheMeanConfidenceOfItsLastNHitsReachesTheBar) {
  TrackerOptions o = three_of_five();
  o.confirm_min_confidence = 0.5;  // M = 3 of N = 5
  Tracker t(o);
  const Eigen::Vector3d p(15, 2, 3);
  // Three hits at 0.3, 0.4, 0.5 (mean 0.4): M of N is reached, the mean is not; the track stays tentative.
  t.update(frame_utime(0), {meas(p, 0.2, 0.3)});
  t.update(frame_utime(1), {meas(p, 0.2, 0.4)});
  t.update(frame_utime(2), {meas(p, 0.2, 0.5)});
  EXPECT_TRUE(t.confirmed(frame_utime(2)).empty());
  EXPECT_EQ(t.num_tentative(), 1u);
  EXPECT_EQ(t.stats().confirmations_held, 1);
  EXPECT_EQ(t.num_held(), 1u);
  // 0.3 0.4 0.5 0.6: mean 0.45, still held (and counted once).
  t.update(frame_utime(3), {meas(p, 0.2, 0.6)});
  EXPECT_TRUE(t.confirmed(frame_utime(3)).empty());
  // A miss leaves the window of hits as it is; then 0.3 0.4 0.5 0.6 0.7: mean 0.5, confirmed.
  t.update(frame_utime(4), {});
  EXPECT_TRUE(t.confirmed(frame_utime(4)).empty());
  t.update(frame_utime(5), {meas(p, 0.2, 0.7)});
  const auto out = t.confirmed(frame_utime(5));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].track_id, 1);
  EXPECT_EQ(t.stats().confirmations_held, 1);
  EXPECT_EQ(t.stats().confirmations, 1);
  EXPECT_EQ(t.num_held(), 0u);
  // The mean is over the last N hits only: after two hits at 0.2, hits at 0.55 confirm the track once both low ones
  // have left the window (0.2 0.2 0.55 0.55 0.55: mean 0.41; 0.2 and four 0.55: 0.48; five 0.55: confirmed).
  Tracker u(o);
  const Eigen::Vector3d r(-10, 4, 2);
  int k = 10;
  u.update(frame_utime(k++), {meas(r, 0.2, 0.2)});
  u.update(frame_utime(k++), {meas(r, 0.2, 0.2)});
  for (int i = 0; i < 4; ++i) {
    u.update(frame_utime(k), {meas(r, 0.2, 0.55)});
    EXPECT_TRUE(u.confirmed(frame_utime(k)).empty()) << i;
    ++k;
  }
  u.update(frame_utime(k), {meas(r, 0.2, 0.55)});
  EXPECT_EQ(u.confirmed(frame_utime(k)).size(), 1u);
  // Out of range values are named.
  TrackerOptions bad;
  bad.birth_min_confidence = 1.5;
  bad.confirm_min_confidence = -0.1;
  const auto problems = bad.validate();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_NE(problems[0].find("tracker.birth_min_confidence = 1.5"), std::string::npos) << problems[0];
  EXPECT_NE(problems[1].find("tracker.confirm_min_confidence = -0.1"), std::string::npos) << problems[1];
}

TEST(Tracker, DeletesAfterTheTimeoutAndWithoutReacquisitionNeverReusesIds) {
  TrackerOptions o = three_of_five();
  o.death_timeout_s = 0.5;
  o.reacquire_s = 0.0;
  Tracker t(o);
  for (int k = 0; k < 5; ++k) t.update(frame_utime(k), {meas({15, 0, 3})});
  ASSERT_EQ(t.confirmed(frame_utime(4)).size(), 1u);
  for (int k = 5; k <= 9; ++k) t.update(frame_utime(k), {});  // 0.5 s without a hit: kept
  EXPECT_EQ(t.num_confirmed(), 1u);
  t.update(frame_utime(10), {});  // 0.6 s: deleted
  EXPECT_EQ(t.num_confirmed(), 0u);
  EXPECT_EQ(t.stats().deaths, 1);
  for (int k = 11; k < 14; ++k) t.update(frame_utime(k), {meas({15, 0, 3})});
  const auto out = t.confirmed(frame_utime(13));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].track_id, 2);
}

// Re-acquisition (tracker.reacquire_s): a target unseen for 3 s (its track deleted after 0.5 s) that comes back 4 m
// from its last hit (within 2 m + 5 m/s x 3.x s) is confirmed with its old id; beyond the gate, after reacquire_s, or
// with it off, it gets a new one. Of two deleted tracks the nearer gives its id, and each id is given once.
TEST(Tracker, ATargetThatComesBackNearWhereItWasLostKeepsItsId) {
  struct Case {
    const char* what;
    double reacquire_s;
    Eigen::Vector3d back_at;
    int unseen_frames;
    int32_t expected_id;
  };
  const Eigen::Vector3d a(15, 0, 3);
  for (const Case& c :
       {Case{"back 4 m away after 3 s", 10.0, {15, 4, 3}, 30, 1}, Case{"reacquisition off", 0.0, {15, 4, 3}, 30, 2},
        Case{"beyond the gate: 20 m after 3 s", 10.0, {15, 20, 3}, 30, 2},
        Case{"after reacquire_s", 2.0, {15, 4, 3}, 30, 2}}) {
    SCOPED_TRACE(c.what);
    TrackerOptions o = three_of_five();
    o.death_timeout_s = 0.5;
    o.reacquire_s = c.reacquire_s;
    Tracker t(o);
    int k = 0;
    for (; k < 5; ++k) t.update(frame_utime(k), {meas(a)});
    ASSERT_EQ(t.confirmed(frame_utime(k - 1)).at(0).track_id, 1);
    for (const int end = k + c.unseen_frames; k < end; ++k) t.update(frame_utime(k), {});
    ASSERT_EQ(t.num_confirmed(), 0u);
    for (const int end = k + 3; k < end; ++k) t.update(frame_utime(k), {meas(c.back_at)});
    const auto out = t.confirmed(frame_utime(k - 1));
    ASSERT_EQ(out.size(), 1u);
    EXPECT_EQ(out[0].track_id, c.expected_id);
    EXPECT_EQ(t.stats().reacquired, c.expected_id == 1 ? 1 : 0);
  }

  // Two targets lost together; one comes back nearer the second's last hit: it takes the second's id; the other,
  // back later near the first's, takes the first's.
  TrackerOptions o = three_of_five();
  o.death_timeout_s = 0.5;
  Tracker t(o);
  const Eigen::Vector3d b(15, 6, 3);
  int k = 0;
  for (; k < 5; ++k) t.update(frame_utime(k), {meas(a), meas(b)});
  auto out = t.confirmed(frame_utime(k - 1));
  ASSERT_EQ(out.size(), 2u);
  const int32_t id_a = (out[0].p_target_in_world - a).norm() < 1 ? out[0].track_id : out[1].track_id;
  const int32_t id_b = id_a == out[0].track_id ? out[1].track_id : out[0].track_id;
  for (const int end = k + 10; k < end; ++k) t.update(frame_utime(k), {});
  ASSERT_EQ(t.num_confirmed(), 0u);
  for (const int end = k + 3; k < end; ++k) t.update(frame_utime(k), {meas({15, 5, 3})});
  out = t.confirmed(frame_utime(k - 1));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].track_id, id_b) << "the nearer remembered track";
  for (const int end = k + 3; k < end; ++k) t.update(frame_utime(k), {meas({15, 5, 3}), meas({15, 0.5, 3})});
  out = t.confirmed(frame_utime(k - 1));
  ASSERT_EQ(out.size(), 2u);
  EXPECT_NE(out[0].track_id, out[1].track_id);
  EXPECT_TRUE((out[0].track_id == id_a) != (out[1].track_id == id_a)) << "the first's id given once, to the other";
  EXPECT_EQ(t.stats().reacquired, 2);
}

TEST(Tracker, GatesOutADetectionFarFromTheTrack) {
  Tracker t(three_of_five());
  for (int k = 0; k < 5; ++k) t.update(frame_utime(k), {meas({15, 0, 3}, 0.1)});
  // 3 m away with sigma 0.1 m: far outside the 99 % gate; it starts a tentative track instead.
  t.update(frame_utime(5), {meas({15, 3, 3}, 0.1)});
  const auto out = t.confirmed(frame_utime(5));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_LT((out[0].p_target_in_world - Eigen::Vector3d(15, 0, 3)).norm(), 0.1);
  EXPECT_EQ(out[0].source_utime, frame_utime(4));
  EXPECT_EQ(t.num_tentative(), 1u);
}

TEST(Tracker, ABurstOfFalsePositivesCreatesNoConfirmedTrack) {
  // One real target plus, for 6 frames, 8 false positives per frame uniform in a 60 m cube (seed 11).
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-30, 30);
  Detections det(12);
  Tracker t(three_of_five());
  int max_confirmed = 0;
  for (int k = 0; k < 40; ++k) {
    std::vector<WorldMeasurement> z{det(circle(k * 0.1, 2.0))};
    if (k >= 10 && k < 16)
      for (int i = 0; i < 8; ++i) z.push_back(meas({u(rng) + 30, u(rng), u(rng) + 30}, 0.5, 0.6));
    ASSERT_TRUE(t.update(frame_utime(k), z));
    max_confirmed = std::max(max_confirmed, static_cast<int>(t.confirmed(frame_utime(k)).size()));
  }
  EXPECT_EQ(max_confirmed, 1);
  EXPECT_EQ(t.stats().confirmations, 1);
  EXPECT_GE(t.stats().births, 1 + 6 * 8 - 2);  // (nearly) every false positive started a tentative track
  EXPECT_EQ(t.num_tentative(), 0u);
  const auto out = t.confirmed(frame_utime(39));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].track_id, 1);
}

/// Two targets crossing: A flies east, B north; both pass (20, 0, 5) at t = 4 s at 3 m/s, 90 degrees apart, seen from
/// the origin (range noise 5 %, about 1 m, along A's path; noise seed `seed`), 3-of-5 birth with `options`. Returns
/// the frames, from the first with both tracks confirmed, where the track nearer to A is not the id A had first (or
/// fewer than two tracks are out), and the tracker's stats.
std::pair<int, TrackerStats> crossing_id_errors(unsigned seed, TrackerOptions options) {
  Detections det(seed);
  Tracker t(options);
  const Eigen::Vector3d v_a(3, 0, 0), v_b(0, 3, 0);
  auto a = [&](double s) -> Eigen::Vector3d { return Eigen::Vector3d(20, 0, 5) + v_a * (s - 4); };
  auto b = [&](double s) -> Eigen::Vector3d { return Eigen::Vector3d(20, 0, 5) + v_b * (s - 4); };
  int id_a = 0, id_b = 0, errors = 0;
  for (int k = 0; k <= 80; ++k) {
    const double s = k * 0.1;
    std::vector<WorldMeasurement> z{det(b(s)), det(a(s))};
    if (!t.update(frame_utime(k), z)) return {1000, t.stats()};
    const auto out = t.confirmed(frame_utime(k));
    if (k < 2) continue;
    if (out.size() != 2u) {
      ++errors;
      continue;
    }
    // Which output is which target: the pairing with the smaller sum of state distances (position in m, velocity in
    // m/s over one second): the velocities tell the two apart where the positions meet.
    const auto d = [&](const TrackOutput& o, const Eigen::Vector3d& p, const Eigen::Vector3d& v) {
      return (o.p_target_in_world - p).squaredNorm() + (o.v_target_in_world - v).squaredNorm();
    };
    const bool first_is_a = d(out[0], a(s), v_a) + d(out[1], b(s), v_b) < d(out[0], b(s), v_b) + d(out[1], a(s), v_a);
    const int now_a = first_is_a ? out[0].track_id : out[1].track_id;
    const int now_b = first_is_a ? out[1].track_id : out[0].track_id;
    if (id_a == 0) id_a = now_a, id_b = now_b;
    if (now_a != id_a || now_b != id_b) ++errors;
  }
  return {errors, t.stats()};
}

TEST(Tracker, TwoCrossingTargetsKeepTheirIds) {
  // Judged in every frame, through the crossing too: where the positions meet, the velocities tell the tracks apart;
  // the two tracks agree in state while they pass, and tracker.merge_after_s keeps them from being merged.
  const auto [errors, stats] = crossing_id_errors(5, three_of_five());
  EXPECT_EQ(errors, 0);
  EXPECT_EQ(stats.confirmations, 2);
  EXPECT_EQ(stats.merges, 0);
}

TEST(Tracker, CrossingTargetsKeepTheirIdsOverFortySeedsAndDidNotBefore) {
  // The rule before: the optimal assignment in every frame, tracks merged as soon as they agree.
  TrackerOptions before = three_of_five();
  before.merge_after_s = 0;
  before.ambiguity_chi2 = 0;
  TrackerOptions now = three_of_five();
  if (const char* m = std::getenv("WINGMAN_CROSSING_AMBIGUITY")) now.ambiguity_chi2 = std::atof(m);
  if (const char* m = std::getenv("WINGMAN_CROSSING_MERGE_AFTER")) now.merge_after_s = std::atof(m);
  int failed = 0, failed_before = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    failed += crossing_id_errors(seed, now).first > 0;
    failed_before += crossing_id_errors(seed, before).first > 0;
  }
  std::printf("crossings of 40 seeds with ids wrong: %d now, %d with the rule before\n", failed, failed_before);
  EXPECT_EQ(failed, 0);
  // Measured 2 of 40 (two merges) with GCC, 2 of 40 (swaps at the crossing) with clang and ASan.
  EXPECT_GT(failed_before, 0);
}

TEST(Tracker, DuplicateDetectionsOfOneTargetGiveOneTrack) {
  // Every frame the same target is detected twice, 5 cm apart (two overlapping boxes): the spare
  // detection keeps starting tentative tracks, which are never confirmed as a second target.
  Tracker t(three_of_five());
  for (int k = 0; k < 30; ++k) {
    const Eigen::Vector3d p(15 + 0.2 * k, 0, 3);
    ASSERT_TRUE(t.update(frame_utime(k), {meas(p, 0.2), meas(p + Eigen::Vector3d(0, 0.05, 0), 0.2)}));
    const auto out = t.confirmed(frame_utime(k));
    if (k < 2) continue;
    ASSERT_EQ(out.size(), 1u) << "frame " << k;
    EXPECT_EQ(out[0].track_id, 1);
  }
  EXPECT_EQ(t.stats().confirmations, 1);
  EXPECT_GE(t.stats().merges, 1);
}

TEST(Tracker, TwoConfirmedTracksOfOneTargetMergeIntoTheOlderId) {
  // Merging off: two targets 0.3 m apart with the same velocity become tracks 1 and 2. When merging
  // is turned on (a fresh tracker with the same input), they are one target and keep id 1.
  TrackerOptions off = three_of_five();
  off.merge_chi2 = 0;
  Tracker separate(off), merged(three_of_five());
  for (int k = 0; k < 10; ++k) {
    const Eigen::Vector3d p(15 + 0.2 * k, 0, 3);
    const std::vector<WorldMeasurement> z{meas(p, 0.2), meas(p + Eigen::Vector3d(0, 0.3, 0), 0.2)};
    separate.update(frame_utime(k), z);
    merged.update(frame_utime(k), z);
  }
  EXPECT_EQ(separate.confirmed(frame_utime(9)).size(), 2u);
  const auto out = merged.confirmed(frame_utime(9));
  ASSERT_EQ(out.size(), 1u);
  EXPECT_EQ(out[0].track_id, 1);
}

struct Rms {
  double raw = 0, window = 0, kalman = 0;
};

// Runs the three estimators on the same detections of a target on the circle; RMS position error at
// each frame's exposure time, after 3 s of settling, over 60 s.
Rms rms_on_circle(double speed, unsigned seed) {
  Detections det(seed);
  TrackerOptions ko = three_of_five();
  TrackerOptions wo = three_of_five();
  wo.mode = "sliding_window";
  Tracker kalman(ko), window(wo);
  double se_raw = 0, se_window = 0, se_kalman = 0;
  int n = 0;
  for (int k = 0; k < 600; ++k) {
    const double s = k * 0.1;
    const Eigen::Vector3d truth = circle(s, speed);
    const WorldMeasurement z = det(truth);
    kalman.update(frame_utime(k), {z});
    window.update(frame_utime(k), {z});
    if (s < 3.0) continue;
    const auto ok = kalman.confirmed(frame_utime(k));
    const auto ow = window.confirmed(frame_utime(k));
    EXPECT_EQ(ok.size(), 1u);
    EXPECT_EQ(ow.size(), 1u);
    if (ok.size() != 1 || ow.size() != 1) return {};
    se_raw += (z.p_target_in_world - truth).squaredNorm();
    se_window += (ow[0].p_target_in_world - truth).squaredNorm();
    se_kalman += (ok[0].p_target_in_world - truth).squaredNorm();
    ++n;
  }
  return {std::sqrt(se_raw / n), std::sqrt(se_window / n), std::sqrt(se_kalman / n)};
}

TEST(TrackerAccuracy, KalmanBeatsRawAndSlidingWindowAt0p5To5MetresPerSecond) {
  for (const double speed : {0.5, 1.0, 2.0, 3.5, 5.0}) {
    const Rms r = rms_on_circle(speed, 100 + static_cast<unsigned>(speed * 10));
    std::printf("[ measured ] speed %.1f m/s: RMS raw %.3f m, sliding window (n_f=5) %.3f m, Kalman %.3f m\n", speed,
                r.raw, r.window, r.kalman);
    EXPECT_LT(r.kalman, r.raw) << "speed " << speed;
    EXPECT_LT(r.kalman, r.window) << "speed " << speed;
  }
}

// Detections arrive 0.3 s after exposure. At each "now", the newest processed image is 0.3 s old:
// compare the track predicted to now (lag compensation) with the track at its source time, both
// against the truth now. A straight 20 s pass at constant speed through (20, 0, 5) diagonally
// across the line of sight; error along the direction of motion (bias) and RMS.
TEST(TrackerAccuracy, LagCompensationRemovesTheVelocityTimesLatencyBias) {
  const int64_t latency_us = 300'000;
  for (const double speed : {0.5, 2.0, 5.0}) {
    Detections det(77);
    Tracker t(three_of_five());
    const Eigen::Vector3d dir = Eigen::Vector3d(1, 1, 0).normalized();
    auto truth = [&](int64_t utime) -> Eigen::Vector3d {
      return Eigen::Vector3d(20, 0, 5) + dir * speed * (seconds(utime) - 10);
    };
    double bias_pred = 0, bias_raw = 0, se_pred = 0, se_raw = 0;
    int n = 0, fresh = 0;
    for (int k = 0; k < 200; ++k) {
      const int64_t exposure = frame_utime(k);
      t.update(exposure, {det(truth(exposure))});
      const int64_t now = exposure + latency_us;
      if (k < 30) continue;
      const auto pred = t.confirmed(now);
      const auto raw = t.confirmed(exposure);
      ASSERT_EQ(pred.size(), 1u) << "frame " << k;
      ASSERT_EQ(raw.size(), 1u) << "frame " << k;
      EXPECT_EQ(pred[0].predicted_utime, now);
      EXPECT_EQ(raw[0].predicted_utime, exposure);
      fresh += pred[0].source_utime == exposure;
      const Eigen::Vector3d e_pred = pred[0].p_target_in_world - truth(now);
      const Eigen::Vector3d e_raw = raw[0].p_target_in_world - truth(now);
      bias_pred += e_pred.dot(dir);
      bias_raw += e_raw.dot(dir);
      se_pred += e_pred.squaredNorm();
      se_raw += e_raw.squaredNorm();
      ++n;
    }
    bias_pred /= n;
    bias_raw /= n;
    const double rms_pred = std::sqrt(se_pred / n), rms_raw = std::sqrt(se_raw / n);
    std::printf(
        "[ measured ] lag 0.3 s, speed %.1f m/s: bias along track unpredicted %.3f m (-v*lag = %.3f), predicted "
        "%.3f m; RMS unpredicted %.3f m, predicted %.3f m\n",
        speed, bias_raw, -speed * 0.3, bias_pred, rms_raw, rms_pred);
    EXPECT_GE(fresh, n * 95 / 100) << "detections should update the track (gate 99.9 %)";
    EXPECT_NEAR(bias_raw, -speed * 0.3, 0.1 + 0.05 * speed);  // the lag bias is there without prediction
    EXPECT_LT(std::abs(bias_pred), 0.1);                      // and gone with it
    // Predicting 0.3 s ahead multiplies the velocity noise; it pays in RMS once v * lag dominates.
    if (speed >= 2.0) {
      EXPECT_LT(rms_pred, rms_raw);
    }
  }
}

TEST(Tracker, PredictionIsLimitedToTheHorizonAndNeverGoesBack) {
  TrackerOptions o = three_of_five();
  o.max_prediction_s = 0.5;
  Tracker t(o);
  for (int k = 0; k < 10; ++k) t.update(frame_utime(k), {meas({10 + 0.2 * k, 0, 0}, 0.01)});
  const auto far = t.confirmed(frame_utime(9) + 2'000'000);
  ASSERT_EQ(far.size(), 1u);
  EXPECT_EQ(far[0].predicted_utime, frame_utime(9) + 500'000);
  EXPECT_NEAR(far[0].p_target_in_world.x(), 11.8 + 0.5 * 2, 0.05);
  const auto back = t.confirmed(frame_utime(5));
  EXPECT_EQ(back[0].predicted_utime, frame_utime(9));
}

TEST(Tracker, SlidingWindowPublishesTheMeanOfTheLastNfMeasurements) {
  TrackerOptions o = three_of_five();
  o.mode = "sliding_window";
  Tracker t(o);
  for (int k = 0; k < 8; ++k) t.update(frame_utime(k), {meas({10 + 0.01 * k * k, 1, 2}, 0.1)});
  const auto out = t.confirmed(frame_utime(7) + 300'000);
  ASSERT_EQ(out.size(), 1u);
  const double mean_x = 10 + 0.01 * (9 + 16 + 25 + 36 + 49) / 5.0;  // frames 3..7
  EXPECT_NEAR(out[0].p_target_in_world.x(), mean_x, 1e-12);
  EXPECT_NEAR(out[0].p_target_in_world.y(), 1, 1e-12);
  EXPECT_NEAR(out[0].cov_p(0, 0), 0.01 / 5, 1e-15);
  EXPECT_NEAR(out[0].v_target_in_world.x(), 0.01 * (49 - 9) / 0.4, 1e-9);
  EXPECT_EQ(out[0].predicted_utime, frame_utime(7));  // not predicted: the thesis's behaviour
}

TEST(Tracker, MostConfidentModeFollowsTheBestDetectionAndPublishesOneTarget) {
  // Each frame: the target (confidence 0.9) and a random false positive (0.5); twice a false
  // positive with confidence 0.95 far away. Seed 9.
  TrackerOptions o = three_of_five();
  o.mode = "most_confident";
  Tracker t(o);
  Detections det(9);
  std::uniform_real_distribution<double> u(-20, 20);
  for (int k = 0; k < 50; ++k) {
    const Eigen::Vector3d truth = circle(k * 0.1, 2.0);
    std::vector<WorldMeasurement> z{det(truth, 0.9), meas({u(det.rng()) + 40, u(det.rng()), 5}, 0.5, 0.5)};
    if (k == 20 || k == 35) z.push_back(meas({-30, 30, 10}, 0.5, 0.95));
    ASSERT_TRUE(t.update(frame_utime(k), z));
    const auto out = t.confirmed(frame_utime(k));
    if (k < 2) continue;
    ASSERT_EQ(out.size(), 1u) << "frame " << k;
    EXPECT_EQ(out[0].track_id, 1);
    EXPECT_LT((out[0].p_target_in_world - truth).norm(), 1.5) << "frame " << k;
  }
  EXPECT_EQ(t.stats().confirmations, 1);
}

}  // namespace
