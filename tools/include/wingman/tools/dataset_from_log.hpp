// SPDX-License-Identifier: MIT
// `wingman dataset from-log`: labelled training images from a simulated flight's log (camera frames + ground truth).
#pragma once

#include <cstdint>
#include <ostream>
#include <string>
#include <vector>

namespace wingman::tools {

/// One run of `wingman dataset from-log`.
struct DatasetFromLogRequest {
  std::vector<std::string> logs;  ///< LCM logs recorded with the camera images and the simulator's GROUND_TRUTH
  std::string out_dir;            ///< dataset folder; created, or extended when it already holds from-log images
  std::string split = "train";    ///< train or val: every image of these logs goes there (neighbouring frames
                                  ///< are near-duplicates, so a flight is never split between train and val)
  std::string image_channel = "IMAGE_CAM0";    ///< image_t channel
  std::string truth_channel = "GROUND_TRUTH";  ///< ground_truth_t channel (boxes of the rendered frames)
  int every = 1;                               ///< keep every Nth image of each log (>= 1), counted by image
  double min_box_px = 2.0;           ///< a visible box narrower or lower than this (pixels, after clipping) is dropped
  bool keep_negatives = true;        ///< write frames without a visible drone too (empty label files)
  std::string image_format = "jpg";  ///< jpg or png
  int jpeg_quality = 92;             ///< 1..100
};

/// What a run wrote.
struct DatasetFromLogSummary {
  std::string out_dir;
  int images = 0;       ///< images written
  int boxes = 0;        ///< boxes written over those images
  int negatives = 0;    ///< of the images, those without a box
  int skipped = 0;      ///< images passed over by --every, or negatives when keep_negatives is false
  int unmatched = 0;    ///< images whose ground truth (same image seq) is not in the log
  int undecodable = 0;  ///< messages on the two channels that did not decode or validate (dropped, counted)
  double seconds = 0.0;
  /// "wrote 120 images (118 boxes, 2 negatives) to DIR/images/train from 1 log in 12.3 s (480 skipped, 0 unmatched,
  /// 0 undecodable)".
  std::string one_line() const;
};

/// Writes, per kept image of each log, `images/<split>/<log stem>_<seq>.<jpg|png>` and
/// `labels/<split>/<log stem>_<seq>.txt` (YOLO: one `0 cx cy w h` line per visible drone, the renderer's exact box of
/// the drone's silhouette, clipped to the image), pairing each image_t with the ground_truth_t whose image_seq is the
/// image's seq and whose boxes carry the image's camera_id. Then (re)writes `data.yaml` (train: images/train,
/// val: images/val). Existing files are never overwritten: an image name already present is an error.
/// Throws std::invalid_argument for a bad request, std::runtime_error naming the log or file for I/O problems and
/// for a log with images but no ground truth on `truth_channel` (record flights with the simulator's ground truth).
DatasetFromLogSummary run_dataset_from_log(const DatasetFromLogRequest& request, std::ostream& progress);

}  // namespace wingman::tools
