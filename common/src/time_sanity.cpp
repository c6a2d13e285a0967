// SPDX-License-Identifier: MIT
// Time sanity of time-keyed inputs: the stage clock, checked ages, resync.
#include "wingman/common/time_sanity.hpp"

#include "wingman/common/config.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace wingman::common {
namespace {

int64_t to_us(double seconds) { return static_cast<int64_t>(std::llround(seconds * 1e6)); }

// b - a for a <= b, exact (at most 2^64 - 1) where int64_t subtraction would overflow.
uint64_t distance(int64_t a, int64_t b) { return static_cast<uint64_t>(b) - static_cast<uint64_t>(a); }

// A time difference of hostile size, in seconds, for messages.
double seconds_between(int64_t a, int64_t b) {
  return a <= b ? static_cast<double>(distance(a, b)) * 1e-6 : -static_cast<double>(distance(b, a)) * 1e-6;
}

}  // namespace

std::vector<std::string> TimeSanityOptions::validate() const {
  std::vector<std::string> p;
  // An upper bound keeps the microsecond conversion in range (a day is far beyond any sensible bound).
  if (!(max_ahead_s > 0) || !(max_ahead_s <= 86400))
    p.push_back(problem("time.max_ahead_s", max_ahead_s, "must be a finite number > 0 and <= 86400"));
  if (!(resync_after_s > 0) || !(resync_after_s <= 86400))
    p.push_back(problem("time.resync_after_s", resync_after_s, "must be a finite number > 0 and <= 86400"));
  return p;
}

int64_t TimeSanityOptions::max_ahead_us() const { return to_us(max_ahead_s); }
int64_t TimeSanityOptions::resync_after_us() const { return to_us(resync_after_s); }

std::optional<int64_t> age_us(int64_t now, int64_t stamp) {
  int64_t age = 0;
  if (__builtin_sub_overflow(now, stamp, &age)) return std::nullopt;
  return age;
}

bool is_fresh(int64_t now, int64_t stamp, int64_t max_age_us, int64_t ahead_tolerance_us) {
  const std::optional<int64_t> age = age_us(now, stamp);
  return age && *age <= max_age_us && *age >= -ahead_tolerance_us;
}

StageClock::StageClock(TimeSanityOptions options) : options_(options) {
  const auto problems = options_.validate();
  if (!problems.empty()) {
    std::string all = "invalid TimeSanityOptions:";
    for (const auto& q : problems) all += " " + q + ";";
    throw std::invalid_argument(all);
  }
  max_ahead_us_ = options_.max_ahead_us();
  resync_after_us_ = options_.resync_after_us();
}

int StageClock::add_input(std::string field, std::string noun, bool strict) {
  Input in;
  in.field = std::move(field);
  in.noun = std::move(noun);
  in.strict = strict;
  inputs_.push_back(std::move(in));
  return static_cast<int>(inputs_.size()) - 1;
}

std::optional<int64_t> StageClock::previous(int input) const { return inputs_.at(static_cast<size_t>(input)).previous; }

TimeAdmission StageClock::admit(int input, int64_t utime) {
  Input& in = inputs_.at(static_cast<size_t>(input));
  using V = TimeAdmission::Verdict;
  if (now_ && utime > *now_ && distance(*now_, utime) > static_cast<uint64_t>(max_ahead_us_)) {
    return refuse(in, utime, V::kAhead,
                  fmt::format("{} = {}: {:.3f} s ahead of the newest message time {} (time.max_ahead_s = {})", in.field,
                              utime, seconds_between(*now_, utime), *now_, options_.max_ahead_s));
  }
  if (in.previous && (utime < *in.previous || (in.strict && utime == *in.previous))) {
    const bool duplicate = utime == *in.previous;
    return refuse(
        in, utime, duplicate ? V::kDuplicate : V::kOutOfOrder,
        fmt::format("{} = {}: {} the previous {} ({}): {}", in.field, utime, in.strict ? "not after" : "before",
                    in.noun, *in.previous, duplicate ? "duplicate" : "out of order"));
  }
  in.previous = utime;
  in.refused_first.reset();
  in.refused_last.reset();
  if (!now_ || utime > *now_) now_ = utime;
  return {};
}

TimeAdmission StageClock::refuse(Input& in, int64_t utime, TimeAdmission::Verdict verdict, std::string problem) {
  // The run of refused messages: increasing times, each at most resync_after_s after the one before (a stream,
  // not scattered lies); anything else starts a new run.
  if (!in.refused_last || utime <= *in.refused_last ||
      distance(*in.refused_last, utime) > static_cast<uint64_t>(resync_after_us_)) {
    in.refused_first = utime;
  }
  in.refused_last = utime;
  if (distance(*in.refused_first, utime) < static_cast<uint64_t>(resync_after_us_)) {
    TimeAdmission refused;
    refused.verdict = verdict;
    refused.problem = std::move(problem);
    return refused;
  }
  // Resync: this input's times are the real ones; the stage forgets what lies too far after them.
  const double refused_s = static_cast<double>(distance(*in.refused_first, utime)) * 1e-6;
  in.previous = utime;
  in.refused_first.reset();
  in.refused_last.reset();
  now_ = utime;
  for (Input& other : inputs_) {
    if (&other == &in || !other.previous) continue;
    if (*other.previous > utime && distance(utime, *other.previous) > static_cast<uint64_t>(max_ahead_us_)) {
      other.previous.reset();
    } else if (*other.previous > *now_) {
      now_ = other.previous;
    }
  }
  ++resyncs_;
  TimeAdmission resynced;
  resynced.verdict = TimeAdmission::Verdict::kResynced;
  resynced.problem = fmt::format(
      "{} = {}: every {} refused for {:.3f} s of message time: the stage's clock restarts from it "
      "(time.resync_after_s = {})",
      in.field, utime, in.noun, refused_s, options_.resync_after_s);
  return resynced;
}

}  // namespace wingman::common
