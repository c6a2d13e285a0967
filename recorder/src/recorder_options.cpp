// SPDX-License-Identifier: MIT
// Validation of RecorderOptions.
#include "wingman/recorder/recorder_options.hpp"

#include "wingman/recorder/channel_pattern.hpp"

#include <wingman/common/config.hpp>

namespace wingman::recorder {
namespace {

void check_patterns(const std::string& key, const std::vector<std::string>& patterns, std::vector<std::string>& p) {
  for (const auto& pattern : patterns) {
    if (std::string why; !ChannelPattern::compile(pattern, &why))
      p.push_back(
          common::problem(key, pattern, "not a usable channel pattern (POSIX extended regular expression): " + why));
  }
}

}  // namespace

std::vector<std::string> RecorderOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (directory.empty()) p.push_back(problem("output.directory", directory, "must not be empty"));
  if (file_prefix.empty() || file_prefix.find('/') != std::string::npos)
    p.push_back(problem("output.file_prefix", file_prefix, "must be a non-empty file name part without '/'"));
  if (!(max_segment_mib >= 0.01 && max_segment_mib <= 1024.0 * 1024.0))
    p.push_back(problem("output.max_segment_mib", max_segment_mib, "must be in [0.01, 1048576] MiB"));
  if (!(max_queue_mib >= 0.01 && max_queue_mib <= 4096.0))
    p.push_back(problem("buffer.max_queue_mib", max_queue_mib, "must be in [0.01, 4096] MiB"));
  if (!(retry_period_s >= 0.01 && retry_period_s <= 3600.0))
    p.push_back(problem("errors.retry_period_s", retry_period_s, "must be in [0.01, 3600] seconds"));
  if (include.empty()) p.push_back("channels.include is empty: nothing would be recorded (use [\".*\"] for all)");
  check_patterns("channels.include", include, p);
  check_patterns("channels.exclude", exclude, p);
  return p;
}

}  // namespace wingman::recorder
