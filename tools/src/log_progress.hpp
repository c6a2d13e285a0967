// SPDX-License-Identifier: MIT
// Progress of reading a long LCM log, for people (internal to the tools): common::Progress over the file's bytes.
#pragma once

#include <wingman/common/progress.hpp>

#include <filesystem>
#include <ostream>
#include <string>
#include <system_error>

namespace wingman::tools {

/// Progress through the LCM log at `path`, in MB of the file (update() with each event's byte offset, then
/// finish()): `<label>: 120.3/450.0 MB (26.7 %), 35.2 MB/s, ETA 9s` every 5 s on `out` (nullptr: quiet). A file
/// whose size cannot be read shows no percentage or ETA.
inline common::Progress log_progress(std::ostream* out, const std::string& label, const std::string& path) {
  std::error_code ec;
  const auto size = std::filesystem::file_size(path, ec);
  common::Progress::Options o;
  o.unit = "MB";
  o.scale = 1e-6;
  o.out = out;
  return common::Progress(label, ec ? 0 : static_cast<int64_t>(size), o);
}

}  // namespace wingman::tools
