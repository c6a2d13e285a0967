// SPDX-License-Identifier: MIT
// ChannelPattern: bounded POSIX extended regular expressions over glibc's <regex.h>.
#include "wingman/recorder/channel_pattern.hpp"

#include <fmt/format.h>
#include <regex.h>

#include <cctype>

namespace wingman::recorder {

struct ChannelPattern::Compiled {
  regex_t re{};
  bool ok = false;  // regcomp succeeded: re holds what regfree releases
  Compiled() = default;
  Compiled(const Compiled&) = delete;
  Compiled& operator=(const Compiled&) = delete;
  ~Compiled() {
    if (ok) regfree(&re);
  }
};

namespace {

/// What makes `pattern` unbounded to compile or match, or "" when nothing does. Scans the ERE syntax: a bracket
/// expression (`[...]`, `]` literal first, `[:class:]` inside) is one literal item; `\x` is one escaped character.
std::string unbounded(const std::string& pattern) {
  if (pattern.size() > ChannelPattern::kMaxLength)
    return fmt::format("{} characters: at most {}", pattern.size(), ChannelPattern::kMaxLength);
  int depth = 0;
  for (size_t i = 0; i < pattern.size(); ++i) {
    const char c = pattern[i];
    if (c == '\\') {
      if (i + 1 < pattern.size() && std::isdigit(static_cast<unsigned char>(pattern[i + 1])))
        return fmt::format("a back-reference (\\{}) at character {}: not supported", pattern[i + 1], i + 1);
      ++i;  // the escaped character is a literal
    } else if (c == '[') {
      size_t j = i + 1;
      if (j < pattern.size() && pattern[j] == '^') ++j;
      if (j < pattern.size() && pattern[j] == ']') ++j;  // a leading ']' is literal
      for (; j < pattern.size() && pattern[j] != ']'; ++j) {
        if (pattern[j] == '[' && j + 1 < pattern.size() &&
            (pattern[j + 1] == ':' || pattern[j + 1] == '.' || pattern[j + 1] == '=')) {
          const size_t end = pattern.find(std::string(1, pattern[j + 1]) + "]", j + 2);
          if (end == std::string::npos) break;
          j = end + 1;
        }
      }
      i = j;  // at the closing ']' (or the end: regcomp reports the unbalanced bracket)
    } else if (c == '(') {
      if (++depth > ChannelPattern::kMaxDepth)
        return fmt::format("parentheses nested deeper than {} at character {}", ChannelPattern::kMaxDepth, i + 1);
    } else if (c == ')') {
      // Unbalanced, it would close the anchoring group compile() wraps the pattern in: "a)|(b" would match any
      // name that starts with a or ends with b.
      if (depth == 0) return fmt::format("an unbalanced ')' at character {}", i + 1);
      --depth;
    } else if (c == '{') {
      return fmt::format("counted repetition ('{{') at character {}: not supported", i + 1);
    }
  }
  return "";
}

}  // namespace

ChannelPattern::ChannelPattern(std::string pattern, std::shared_ptr<const Compiled> compiled)
    : pattern_(std::move(pattern)), compiled_(std::move(compiled)) {}

std::optional<ChannelPattern> ChannelPattern::compile(const std::string& pattern, std::string* why) {
  if (const std::string u = unbounded(pattern); !u.empty()) {
    if (why) *why = u;
    return std::nullopt;
  }
  auto compiled = std::make_shared<Compiled>();
  // Anchored at both ends: the whole channel name must match.
  const std::string anchored = "^(" + pattern + ")$";
  const int rc = regcomp(&compiled->re, anchored.c_str(), REG_EXTENDED | REG_NOSUB);
  compiled->ok = rc == 0;
  if (rc != 0) {
    char message[256];
    regerror(rc, &compiled->re, message, sizeof message);
    if (why) *why = message;
    return std::nullopt;
  }
  return ChannelPattern(pattern, std::move(compiled));
}

bool ChannelPattern::matches(const std::string& channel) const {
  if (channel.find('\0') != std::string::npos) return false;  // regexec reads a C string
  return regexec(&compiled_->re, channel.c_str(), 0, nullptr, 0) == 0;
}

}  // namespace wingman::recorder
