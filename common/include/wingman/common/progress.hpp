// SPDX-License-Identifier: MIT
// Progress of a long job, for people: "label: done/total unit (pct %), rate unit/s, ETA 1m05s" every few seconds.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <iostream>
#include <string>

namespace wingman::common {

/// Progress of one job of `total` steps, printed for a person on a stream (stderr by default): one line
/// at most every `every_s` seconds, and a closing line from finish() when the job ran long enough to print one.
/// Wall-clock (steady) time: a display only, no result and no message time depends on it. Not thread-safe: one
/// thread updates it.
///
///   Progress p("wingman dataset synth", 1000, "images", &std::cerr);
///   for (int i = 0; i < 1000; ++i) { work(i); p.update(i + 1); }
///   p.finish();
///
/// prints, every 5 s: `wingman dataset synth: 120/1000 images (12.0 %), 3.41 images/s, ETA 4m18s`.
class Progress {
 public:
  using Clock = std::function<std::chrono::steady_clock::time_point()>;

  struct Options {
    std::string unit;                ///< what is counted, e.g. "images" ("" = bare numbers)
    double scale = 1.0;              ///< shown = counted * scale (e.g. 1e-6 with unit "MB" for bytes); > 0
    double every_s = 5.0;            ///< seconds between lines, > 0
    std::ostream* out = &std::cerr;  ///< where lines go; nullptr = nowhere (a quiet job)
    /// When set, each line (no newline) goes here instead of `out`: a process's logger, e.g.
    /// `[](const std::string& l) { spdlog::info("{}", l); }`.
    std::function<void(const std::string&)> sink;
    Clock clock = std::chrono::steady_clock::now;  ///< the time source (a fake one in tests)
  };

  /// `total` <= 0: the total is unknown (lines without percentage and ETA). Throws std::invalid_argument on a
  /// scale or every_s that is not > 0.
  Progress(std::string label, int64_t total, Options options);
  /// The usual case: Options' defaults with this unit and stream (nullptr = quiet).
  Progress(std::string label, int64_t total, std::string unit, std::ostream* out);

  /// `done` steps are finished (counted from 0 at construction; non-decreasing). Prints a line when every_s has
  /// passed since construction or since the last line, and `done` is short of the total (the closing line is
  /// finish()'s). `note` (e.g. "12 targets found"), when not empty, ends the
  /// line after a semicolon and is kept for finish().
  void update(int64_t done, const std::string& note = "");
  /// One more step finished: update(done() + 1) with the last note.
  void step() { update(done_ + 1, note_); }
  /// The job ended: prints the closing line (`label: done/total unit (100.0 %), rate unit/s, took 4m53s`) when a
  /// line was printed before or the job took at least every_s; short jobs stay silent. Later calls do nothing.
  void finish();

  /// The line update() prints for `done` at time `now` with the last note (no newline).
  std::string line(int64_t done, std::chrono::steady_clock::time_point now) const;
  int64_t done() const { return done_; }
  int64_t total() const { return total_; }

 private:
  std::string label_;
  int64_t total_;
  Options o_;
  std::chrono::steady_clock::time_point start_, last_;
  int64_t done_ = 0;
  std::string note_;
  bool printed_ = false;
  bool finished_ = false;

  void emit(const std::string& line) const;
};

/// `seconds` as people read a duration: "42s", "4m05s", "2h03m" (rounded to whole seconds; negative as 0s).
std::string duration_text(double seconds);

}  // namespace wingman::common
