// SPDX-License-Identifier: MIT
// Time sanity of time-keyed inputs: a stage's clock from message times, future-dated messages refused, ages that
// call data from the future stale, and an order rule that cannot latch.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace wingman::common {

/// Options of the time-sanity policy (keys `time.*` of a process's configuration).
struct TimeSanityOptions {
  /// A message dated more than this ahead of the stage's clock (the newest message time the stage accepted on any of
  /// its time-keyed inputs) is dropped and counted, never adopted as "now". Also the tolerance of cross-input ages:
  /// data from another input dated more than this after the time it is used at is stale, not fresh. Seconds of
  /// message time, finite, > 0.
  double max_ahead_s = 1.0;
  /// Anti-latch: when every message of one input has been refused (dated ahead of the clock, or not after that
  /// input's previous accepted message) for this long of the refused messages' own time, in increasing order, the
  /// stage re-anchors on them (resync): the clock and the input's order restart from the newest, and the stage
  /// forgets the state it built on the old times. A stage therefore recovers within this much message time (plus
  /// one message) after any single bad message, including one that arrived first. Seconds, finite, > 0.
  double resync_after_s = 1.0;

  template <class V>
  void visit(V& v) {
    v("time.max_ahead_s", max_ahead_s,
      "drop a message dated more than this ahead of the newest accepted message time (s); also the tolerance of "
      "data dated after the time it is used at");
    v("time.resync_after_s", resync_after_s,
      "an input whose every message was refused for this long of their own time, in order, re-anchors the clock (s)");
  }
  /// One "key = value: rule" line per problem; empty when valid.
  std::vector<std::string> validate() const;
  /// max_ahead_s in microseconds. Precondition: validate() is empty.
  int64_t max_ahead_us() const;
  /// resync_after_s in microseconds. Precondition: validate() is empty.
  int64_t resync_after_us() const;
};

/// `now - stamp` in microseconds, the age of data stamped `stamp` at message time `now`; nullopt when the difference
/// does not fit in int64_t (hostile times).
std::optional<int64_t> age_us(int64_t now, int64_t stamp);

/// Whether data stamped `stamp` is fresh at message time `now`: -ahead_tolerance_us <= now - stamp <= max_age_us.
/// A negative age (data dated after the time it is used at) beyond the tolerance is stale, never fresh; so is an
/// age that overflows. Use tolerance 0 for two times of one message or one stream (they never run backwards), and
/// TimeSanityOptions::max_ahead_us() across inputs (an own pose may be newer than an image time).
/// Preconditions: max_age_us >= 0, ahead_tolerance_us >= 0.
bool is_fresh(int64_t now, int64_t stamp, int64_t max_age_us, int64_t ahead_tolerance_us = 0);

/// What StageClock::admit decided about one message.
struct TimeAdmission {
  enum class Verdict {
    kAccepted,    ///< in order and not ahead of the clock
    kResynced,    ///< accepted as the anchor of a resync: the caller forgets the state it built on the old times
    kAhead,       ///< refused: dated more than max_ahead_s after the stage's clock
    kOutOfOrder,  ///< refused: before the input's previous accepted message
    kDuplicate,   ///< refused: the same time as the input's previous accepted message (strict inputs)
  };
  Verdict verdict = Verdict::kAccepted;
  /// "" when accepted; for a resync one line saying so (for the log); when refused one line naming the field, its
  /// value and the rule, e.g.
  /// "own_pose_t.utime = 1700001000000000: 1000.000 s ahead of the newest message time 1700000000000000
  /// (time.max_ahead_s = 1)".
  std::string problem;

  bool accepted() const { return verdict == Verdict::kAccepted || verdict == Verdict::kResynced; }
  bool resynced() const { return verdict == Verdict::kResynced; }
};

/// One stage's clock over its time-keyed inputs (one policy for every process): message time only, never the receive
/// clock. Each message of an input is admitted or refused:
///  - the stage's clock is the newest message time accepted on any input (none before the first message, which is
///    accepted whatever its time: there is nothing to compare it with);
///  - a message dated more than max_ahead_s after the clock is refused (kAhead) and never becomes the clock;
///  - a message before its input's previous accepted one (or at the same time, for a strict input) is refused
///    (kOutOfOrder, kDuplicate). Messages behind the clock are otherwise accepted: inputs lag each other (image
///    times lag own-pose times by the detector's latency);
///  - resync (the rule cannot latch): when an input's refused messages have come in increasing order for
///    resync_after_s of their own time with none accepted in between, the newest is accepted as kResynced: it
///    becomes the input's previous time and the clock, and the other inputs whose previous time lies more than
///    max_ahead_s after it forget it (their next message is accepted as a first one). A bad first message, or a
///    source whose time really jumped, thus blinds the stage for at most resync_after_s of message time.
/// Not thread-safe.
class StageClock {
 public:
  /// Throws std::invalid_argument listing options.validate() problems.
  explicit StageClock(TimeSanityOptions options = {});

  /// Declares an input and returns its id for admit(). `field` names the time field in problems
  /// ("own_pose_t.utime"); `noun` names one message ("own pose"); `strict`: a message must be after the input's
  /// previous one (a duplicate time is refused), else at or after it.
  int add_input(std::string field, std::string noun, bool strict);

  /// Decides about a message of input `input` (an id from add_input) dated `utime`; see the class comment.
  TimeAdmission admit(int input, int64_t utime);

  /// The stage's clock: the newest accepted message time; nullopt before the first.
  std::optional<int64_t> now() const { return now_; }
  /// The previous accepted time of `input`; nullopt before its first (or after a resync made it forget).
  std::optional<int64_t> previous(int input) const;
  /// Resyncs so far.
  int64_t resyncs() const { return resyncs_; }
  const TimeSanityOptions& options() const { return options_; }

 private:
  struct Input {
    std::string field;
    std::string noun;
    bool strict = true;
    std::optional<int64_t> previous;       ///< newest accepted time
    std::optional<int64_t> refused_first;  ///< first of the current run of refused messages
    std::optional<int64_t> refused_last;   ///< newest of that run
  };
  TimeAdmission refuse(Input& in, int64_t utime, TimeAdmission::Verdict verdict, std::string problem);

  TimeSanityOptions options_;
  int64_t max_ahead_us_;
  int64_t resync_after_us_;
  std::vector<Input> inputs_;
  std::optional<int64_t> now_;
  int64_t resyncs_ = 0;
};

}  // namespace wingman::common
