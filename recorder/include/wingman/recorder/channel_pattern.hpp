// SPDX-License-Identifier: MIT
// A channel-name pattern of the recorder's channels.include / channels.exclude: a POSIX extended regular expression
// matched against the whole channel name, bounded so that no configuration can make loading or matching unbounded.
#pragma once

#include <memory>
#include <optional>
#include <string>

namespace wingman::recorder {

/// One compiled pattern (glibc's regcomp/regexec, REG_EXTENDED | REG_NOSUB). Accepted: POSIX extended regular
/// expressions (`.`, `*`, `+`, `?`, `|`, `( )`, bracket expressions, `^`, `$`) of at most kMaxLength characters and
/// kMaxDepth levels of parentheses, without back-references (`\1`) or counted repetition (`{m,n}`). Without those two,
/// glibc matches in time polynomial in the pattern and the name (no backtracking), and the limits keep its recursive
/// compiler and its automaton small: a hostile pattern is one error at load, never a crash or a hang (issue 33).
class ChannelPattern {
 public:
  static constexpr size_t kMaxLength = 256;  ///< characters
  static constexpr int kMaxDepth = 16;       ///< nested parentheses

  /// The compiled pattern, or nullopt with `*why` (when not null) saying what is wrong (too long, too deep, a
  /// back-reference or counted repetition, or regcomp's own message).
  static std::optional<ChannelPattern> compile(const std::string& pattern, std::string* why = nullptr);

  /// True when the whole of `channel` matches (the pattern is anchored at both ends).
  bool matches(const std::string& channel) const;

  const std::string& pattern() const { return pattern_; }

 private:
  struct Compiled;
  ChannelPattern(std::string pattern, std::shared_ptr<const Compiled> compiled);
  std::string pattern_;
  std::shared_ptr<const Compiled> compiled_;  // immutable once compiled; regexec only reads it
};

}  // namespace wingman::recorder
