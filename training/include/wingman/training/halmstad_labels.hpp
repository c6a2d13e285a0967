// SPDX-License-Identifier: MIT
// The Halmstad drone detection dataset's label files: one reader for the importer and the track-level metrics.
#pragma once

#include <opencv2/core/types.hpp>

#include <map>
#include <string>
#include <vector>

namespace wingman::training {

/// The label classes in class-id order: DRONE (0), AIRPLANE (1), BIRD (2), HELICOPTER (3).
const std::vector<std::string>& halmstad_label_classes();

/// The class id of a label class name (index in halmstad_label_classes()), or -1 for any other name.
int halmstad_class_id(const std::string& name);

/// One labelled box: its rectangle in 0-based continuous pixels and its class id.
struct HalmstadLabelBox {
  cv::Rect2d rect;
  int cls = 0;
};

/// The fields of one comma-separated line (a trailing '\r' removed from each; a trailing comma gives an empty field).
std::vector<std::string> split_csv_line(const std::string& line);

/// Reads one label CSV (`frame,class,x,y,w,h`, one row per box; MATLAB's pixel convention, so 0.5 px is subtracted from
/// x and y): frame -> its boxes, every class. Blank lines are skipped. Throws DatasetError naming the file and line
/// for a missing file, a bad header, a wrong field count, a frame that is not an integer in 0..INT_MAX, a class other
/// than the four, or a coordinate that is not a finite number (w, h: positive).
std::map<int, std::vector<HalmstadLabelBox>> read_halmstad_labels(const std::string& path);

}  // namespace wingman::training
