// SPDX-License-Identifier: MIT
// The Halmstad label CSVs.
#include "wingman/training/halmstad_labels.hpp"

#include "wingman/training/yolo_dataset.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

namespace wingman::training {

const std::vector<std::string>& halmstad_label_classes() {
  static const std::vector<std::string> kClasses = {"DRONE", "AIRPLANE", "BIRD", "HELICOPTER"};
  return kClasses;
}

int halmstad_class_id(const std::string& name) {
  const auto& classes = halmstad_label_classes();
  const auto it = std::find(classes.begin(), classes.end(), name);
  return it == classes.end() ? -1 : static_cast<int>(it - classes.begin());
}

std::vector<std::string> split_csv_line(const std::string& line) {
  std::vector<std::string> out;
  std::string f;
  std::stringstream ss(line);
  while (std::getline(ss, f, ',')) {
    if (!f.empty() && f.back() == '\r') f.pop_back();
    out.push_back(f);
  }
  if (!line.empty() && line.back() == ',') out.emplace_back();
  return out;
}

std::map<int, std::vector<HalmstadLabelBox>> read_halmstad_labels(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw DatasetError(fmt::format("{}: cannot read the label file", path));
  std::string line;
  std::getline(in, line);
  if (line.rfind("frame,class,x,y,w,h", 0) != 0)
    throw DatasetError(fmt::format("{}:1: expected the header 'frame,class,x,y,w,h', got '{}'", path, line));
  std::map<int, std::vector<HalmstadLabelBox>> boxes;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> f = split_csv_line(line);
    if (f.size() != 6) throw DatasetError(fmt::format("{}:{}: expected 6 fields, got {}", path, line_no, f.size()));
    char* end = nullptr;
    const long frame = std::strtol(f[0].c_str(), &end, 10);
    if (end == f[0].c_str() || *end != '\0' || frame < 0 || frame > std::numeric_limits<int>::max())
      throw DatasetError(fmt::format("{}:{}: field frame = '{}': expected an integer >= 0", path, line_no, f[0]));
    const int cls = halmstad_class_id(f[1]);
    if (cls < 0)
      throw DatasetError(
          fmt::format("{}:{}: field class = '{}': expected DRONE, AIRPLANE, BIRD or HELICOPTER", path, line_no, f[1]));
    double v[4];
    static const char* kNames[] = {"x", "y", "w", "h"};
    for (int k = 0; k < 4; ++k) {
      end = nullptr;
      v[k] = std::strtod(f[2 + k].c_str(), &end);
      if (end == f[2 + k].c_str() || *end != '\0' || !std::isfinite(v[k]) || (k >= 2 && v[k] <= 0))
        throw DatasetError(fmt::format("{}:{}: field {} = '{}': expected a{} number", path, line_no, kNames[k],
                                       f[2 + k], k >= 2 ? " positive" : ""));
    }
    // MATLAB's spatial coordinates put pixel centres at integers: the 0-based left edge is x - 0.5.
    boxes[static_cast<int>(frame)].push_back({cv::Rect2d(v[0] - 0.5, v[1] - 0.5, v[2], v[3]), cls});
  }
  return boxes;
}

}  // namespace wingman::training
