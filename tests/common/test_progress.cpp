// SPDX-License-Identifier: MIT
// Progress lines of long jobs, on a fake clock: when they print and what they say.
#include <wingman/common/progress.hpp>

#include <gtest/gtest.h>

#include <limits>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::common {
namespace {

using std::chrono::milliseconds;
using std::chrono::seconds;
using TimePoint = std::chrono::steady_clock::time_point;

/// A clock that moves only when the test says so.
struct FakeClock {
  TimePoint now{seconds(1000)};
  Progress::Clock fn() {
    return [this] { return now; };
  }
};

Progress::Options options(FakeClock& clock, std::ostream& out, const std::string& unit = "images") {
  Progress::Options o;
  o.unit = unit;
  o.every_s = 5.0;
  o.out = &out;
  o.clock = clock.fn();
  return o;
}

TEST(Progress, PrintsDoneTotalPercentRateAndEtaAtMostEveryPeriod) {
  FakeClock clock;
  std::ostringstream out;
  Progress p("wingman dataset synth", 1000, options(clock, out));
  clock.now += seconds(4);
  p.update(40);
  EXPECT_EQ(out.str(), "");  // 4 s < every_s
  clock.now += seconds(1);
  p.update(50);  // 5 s: 50 images at 10/s, 950 left: 95 s
  EXPECT_EQ(out.str(), "wingman dataset synth: 50/1000 images (5.0 %), 10.0 images/s, ETA 1m35s\n");
  clock.now += seconds(4);
  p.update(90);
  EXPECT_EQ(out.str(), "wingman dataset synth: 50/1000 images (5.0 %), 10.0 images/s, ETA 1m35s\n");  // 4 s since
  clock.now += milliseconds(1000);
  p.update(100);  // 10 s: 100 at 10/s, 900 left
  EXPECT_EQ(out.str(),
            "wingman dataset synth: 50/1000 images (5.0 %), 10.0 images/s, ETA 1m35s\n"
            "wingman dataset synth: 100/1000 images (10.0 %), 10.0 images/s, ETA 1m30s\n");
}

TEST(Progress, FinishPrintsTheClosingLineOnlyAfterALongJob) {
  FakeClock clock;
  std::ostringstream quiet;
  Progress short_job("wingman val", 3, options(clock, quiet));
  clock.now += seconds(2);
  short_job.update(3);
  short_job.finish();
  EXPECT_EQ(quiet.str(), "");  // 2 s: nothing at all

  std::ostringstream out;
  Progress long_job("wingman val", 4000, options(clock, out));
  clock.now += seconds(3723);  // 1 h 2 min 3 s, no update() in between
  long_job.update(3999);       // the percentage rounds down: 100.0 % means done
  EXPECT_EQ(out.str(), "wingman val: 3999/4000 images (99.9 %), 1.07 images/s, ETA 1s\n");
  out.str("");
  clock.now += seconds(77);  // 3800 s in all
  long_job.update(4000);     // all done: no line, finish() closes
  EXPECT_EQ(out.str(), "");
  long_job.finish();
  EXPECT_EQ(out.str(), "wingman val: 4000/4000 images (100.0 %), 1.05 images/s, took 1h03m\n");
  long_job.finish();  // once only
  long_job.update(4000);
  EXPECT_EQ(out.str(), "wingman val: 4000/4000 images (100.0 %), 1.05 images/s, took 1h03m\n");
}

TEST(Progress, UnknownTotalHasNoPercentageOrEta) {
  FakeClock clock;
  std::ostringstream out;
  Progress p("wingman replay", 0, options(clock, out, "events"));
  clock.now += seconds(8);
  p.update(1234);
  EXPECT_EQ(out.str(), "wingman replay: 1234 events, 154 events/s\n");
}

TEST(Progress, ScaledCountsShowOneDecimalAndNoStepsDoneMeansUnknownEta) {
  FakeClock clock;
  std::ostringstream out;
  Progress::Options o = options(clock, out, "MB");
  o.scale = 1e-6;  // bytes shown as MB
  Progress p("wingman eval: reading flight.lcmlog", 250'000'000, o);
  clock.now += seconds(5);
  p.update(0);
  clock.now += seconds(5);
  p.update(25'000'000);
  EXPECT_EQ(out.str(),
            "wingman eval: reading flight.lcmlog: 0.0/250.0 MB (0.0 %), 0.00 MB/s, ETA unknown\n"
            "wingman eval: reading flight.lcmlog: 25.0/250.0 MB (10.0 %), 2.50 MB/s, ETA 1m30s\n");
}

TEST(Progress, StepCountsOneAtATime) {
  FakeClock clock;
  std::ostringstream out;
  Progress p("job", 10, options(clock, out, ""));
  for (int i = 0; i < 4; ++i) p.step();
  EXPECT_EQ(p.done(), 4);
  clock.now += seconds(5);
  p.step();
  EXPECT_EQ(out.str(), "job: 5/10 (50.0 %), 1.00/s, ETA 5s\n");
}

TEST(Progress, ANoteEndsTheLineAndTheClosingLine) {
  FakeClock clock;
  std::ostringstream out;
  Progress p("wingman model box-relation", 200, options(clock, out));
  clock.now += seconds(5);
  p.update(20, "18 targets found");
  clock.now += seconds(15);
  p.update(200, "190 targets found");
  p.finish();
  EXPECT_EQ(out.str(),
            "wingman model box-relation: 20/200 images (10.0 %), 4.00 images/s, ETA 45s; 18 targets found\n"
            "wingman model box-relation: 200/200 images (100.0 %), 10.0 images/s, took 20s; 190 targets found\n");
}

TEST(Progress, ASinkGetsTheLinesInsteadOfTheStream) {
  // A process logs its progress (e.g. the simulator's frames, through spdlog): the lines go to the sink.
  FakeClock clock;
  std::ostringstream out;
  Progress::Options o = options(clock, out, "frames");
  o.every_s = 10.0;
  std::vector<std::string> lines;
  o.sink = [&](const std::string& l) { lines.push_back(l); };
  Progress p("wingman-sim", 600, o);
  clock.now += seconds(10);
  p.update(195);
  clock.now += seconds(10);
  p.update(390);
  p.finish();
  EXPECT_EQ(out.str(), "");
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "wingman-sim: 195/600 frames (32.5 %), 19.5 frames/s, ETA 21s");
  EXPECT_EQ(lines[2], "wingman-sim: 390/600 frames (65.0 %), 19.5 frames/s, took 20s");
}

TEST(Progress, RejectsANonPositivePeriodOrScale) {
  FakeClock clock;
  std::ostringstream out;
  Progress::Options o = options(clock, out);
  o.every_s = 0;
  EXPECT_THROW(Progress("job", 1, o), std::invalid_argument);
  o.every_s = 1;
  o.scale = -1;
  EXPECT_THROW(Progress("job", 1, o), std::invalid_argument);
}

TEST(DurationText, SecondsMinutesAndHours) {
  EXPECT_EQ(duration_text(0.4), "0s");
  EXPECT_EQ(duration_text(-3), "0s");
  EXPECT_EQ(duration_text(42.4), "42s");
  EXPECT_EQ(duration_text(245), "4m05s");
  EXPECT_EQ(duration_text(7380), "2h03m");
  EXPECT_EQ(duration_text(std::numeric_limits<double>::infinity()), "0s");
}

}  // namespace
}  // namespace wingman::common
