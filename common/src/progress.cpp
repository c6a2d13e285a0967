// SPDX-License-Identifier: MIT
// Progress lines for long jobs.
#include "wingman/common/progress.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>
#include <utility>

namespace wingman::common {

namespace {

double seconds_between(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

/// A count as shown: whole numbers without decimals, scaled ones (MB) with one.
std::string count_text(int64_t n, double scale) {
  return scale == 1.0 ? std::to_string(n) : fmt::format("{:.1f}", static_cast<double>(n) * scale);
}

/// Three significant figures, never in exponent form.
std::string rate_text(double r) {
  return r >= 100 ? fmt::format("{:.0f}", r) : r >= 10 ? fmt::format("{:.1f}", r) : fmt::format("{:.2f}", r);
}

}  // namespace

std::string duration_text(double seconds) {
  const int64_t s = std::isfinite(seconds) && seconds > 0 ? std::llround(seconds) : 0;
  if (s >= 3600) return fmt::format("{}h{:02d}m", s / 3600, s / 60 % 60);
  if (s >= 60) return fmt::format("{}m{:02d}s", s / 60, s % 60);
  return fmt::format("{}s", s);
}

Progress::Progress(std::string label, int64_t total, Options options)
    : label_(std::move(label)), total_(total), o_(std::move(options)) {
  if (!(o_.scale > 0)) throw std::invalid_argument(fmt::format("Progress: scale = {}: must be > 0", o_.scale));
  if (!(o_.every_s > 0)) throw std::invalid_argument(fmt::format("Progress: every_s = {}: must be > 0", o_.every_s));
  if (!o_.clock) o_.clock = std::chrono::steady_clock::now;
  start_ = last_ = o_.clock();
}

Progress::Progress(std::string label, int64_t total, std::string unit, std::ostream* out)
    : Progress(std::move(label), total, [&] {
        Options o;
        o.unit = std::move(unit);
        o.out = out;
        return o;
      }()) {}

std::string Progress::line(int64_t done, std::chrono::steady_clock::time_point now) const {
  const std::string unit = o_.unit.empty() ? "" : " " + o_.unit;
  const double elapsed = seconds_between(start_, now);
  const double rate = elapsed > 0 ? static_cast<double>(done) * o_.scale / elapsed : 0.0;
  std::string s = label_ + ": " + count_text(done, o_.scale);
  if (total_ > 0)
    s += fmt::format("/{}{} ({:.1f} %)", count_text(total_, o_.scale), unit,  // rounded down: 100.0 % is done
                     std::floor(1000.0 * static_cast<double>(done) / static_cast<double>(total_)) / 10.0);
  else
    s += unit;
  s += fmt::format(", {}{}/s", rate_text(rate), o_.unit.empty() ? "" : unit);
  if (finished_) {
    s += ", took " + duration_text(elapsed);
  } else if (total_ > 0) {
    const double left = static_cast<double>(total_ - done) * o_.scale;
    s += ", ETA " + (rate > 0 ? duration_text(left / rate) : std::string("unknown"));
  }
  return note_.empty() ? s : s + "; " + note_;
}

void Progress::emit(const std::string& text) const {
  if (o_.sink)
    o_.sink(text);
  else if (o_.out)
    *o_.out << text << std::endl;
}

void Progress::update(int64_t done, const std::string& note) {
  done_ = done;
  note_ = note;
  if (finished_ || (total_ > 0 && done >= total_)) return;  // all done: finish() has the closing line
  const auto now = o_.clock();
  if (seconds_between(last_, now) < o_.every_s) return;
  last_ = now;
  printed_ = true;
  emit(line(done, now));
}

void Progress::finish() {
  if (finished_) return;
  const auto now = o_.clock();
  const bool print = printed_ || seconds_between(start_, now) >= o_.every_s;
  finished_ = true;
  if (print) emit(line(done_, now));
}

}  // namespace wingman::common
