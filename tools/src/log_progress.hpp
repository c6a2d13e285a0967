// SPDX-License-Identifier: MIT
// Progress of reading a long LCM log, for people (internal to the tools).
#pragma once

#include <fmt/format.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <ostream>
#include <string>
#include <utility>

namespace wingman::tools {

/// Prints "<what> NN % of <log>" every few seconds of wall-clock time (progress only; no result depends on it).
class LogProgress {
 public:
  LogProgress(std::ostream* out, const std::string& path, FILE* file, std::string what = "read")
      : out_(out), path_(path), what_(std::move(what)), file_(file) {
    std::error_code ec;
    size_ = out_ ? static_cast<double>(std::filesystem::file_size(path, ec)) : 0.0;
    if (ec) size_ = 0.0;
    last_ = std::chrono::steady_clock::now();
  }
  /// After each event: prints the share read when 3 s have passed since the start or the last print.
  void tick() {
    if (!out_ || size_ <= 0.0) return;
    const auto now = std::chrono::steady_clock::now();
    if (now - last_ < std::chrono::seconds(3)) return;
    last_ = now;
    const long pos = file_ ? std::ftell(file_) : -1;
    if (pos < 0) return;
    *out_ << fmt::format("wingman: {} {:.0f} % of {}", what_, 100.0 * static_cast<double>(pos) / size_, path_)
          << std::endl;
    printed_ = true;
  }
  /// The closing "100 %", when a share was printed before (short logs print nothing).
  void done() {
    if (printed_) *out_ << "wingman: " << what_ << " 100 % of " << path_ << std::endl;
  }

 private:
  std::ostream* out_;
  std::string path_;
  std::string what_;
  FILE* file_;
  double size_ = 0.0;
  bool printed_ = false;
  std::chrono::steady_clock::time_point last_;
};

}  // namespace wingman::tools
