// SPDX-License-Identifier: MIT
// Importing the Halmstad drone detection dataset (videos + per-frame box CSVs) as a YOLO-layout dataset.
#pragma once

#include "wingman/training/box_tightening.hpp"

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace wingman::training {

/// What import_halmstad() samples and writes.
struct HalmstadImportOptions {
  std::string root;     ///< the dataset folder: clips.csv, videos/V_<CLASS>_<nnn>.mp4, labels/V_<CLASS>_<nnn>.csv
  std::string out_dir;  ///< the YOLO-layout dataset to write (images/{train,val}, labels/{train,val}, data.yaml)
  int frame_step = 10;  ///< DRONE clips: every frame_step-th frame (0, step, 2 step, ...), >= 1
  int negative_frame_step = 30;  ///< AIRPLANE / BIRD / HELICOPTER clips (hard negatives, empty labels), >= 1
  bool negatives = true;         ///< include the non-drone clips as negatives
  /// Label the non-drone clips' boxes as classes of their own (1 airplane, 2 bird, 3 helicopter; data.yaml names all
  /// four) instead of writing their frames as empty negatives: the distractors as supervision, for a multi-class model
  bool distractor_classes = false;
  int max_frames_per_clip = 0;     ///< at most this many frames per clip (0 = no limit), >= 0
  double val_fraction = 0.2;       ///< share of clips in val, per (class, distance bin) group, 0..1 (split by clip)
  uint64_t seed = 1;               ///< seeds the clip split
  bool tighten = true;             ///< tighten each drone box (tighten_box); keep the original when that fails
  TightenOptions tightening;       ///< how
  std::vector<std::string> clips;  ///< only these clips (names as in clips.csv); empty = all listed
  /// Clips left out: described as showing two drones with only one labelled (README caveat).
  std::vector<std::string> exclude = {"V_DRONE_005", "V_DRONE_099"};
  int jpeg_quality = 95;  ///< of the written .jpg frames, 1..100

  /// One "field = value: rule" line per invalid field; empty when valid.
  std::vector<std::string> validate() const;
};

/// What was written.
struct HalmstadImportSummary {
  std::vector<std::string> train_clips, val_clips;
  int64_t train_images = 0, val_images = 0;
  int64_t negative_images = 0;   ///< images from non-drone clips (and drone frames without a box)
  int64_t boxes = 0;             ///< drone boxes written
  int64_t distractor_boxes = 0;  ///< with distractor_classes: airplane, bird and helicopter boxes written
  int64_t tightened = 0;         ///< of all boxes written, tightened
  double mean_area_ratio = 0.0;  ///< mean tight area / original area over the tightened boxes

  std::string one_line() const;
  std::string report() const;
};

/// Samples frames from the clips (read sequentially with OpenCV; frame k is the k-th frame read, as the
/// label CSVs count), writes them as images/<split>/<clip>_<frame>.jpg with labels/<split>/<clip>_<frame>.txt
/// (class 0 = drone; empty for negatives, or with distractor_classes 1 airplane, 2 bird, 3 helicopter), data.yaml, and
/// splits.csv (clip, class, distance bin, split). The split does not depend on distractor_classes.
/// Box CSV values are MATLAB's (pixel centres at integers), so 0.5 px is subtracted from x and y.
/// The split is by clip, never by frame: within each (class, distance bin) group the clips are shuffled
/// with `seed` and round(val_fraction * n) of them go to val. `log` (may be empty) gets one line per clip,
/// `progress(clips done, clips in all)` (may be empty) a call after each.
/// Throws std::invalid_argument for invalid options; DatasetError naming the file and line for a missing or
/// malformed clips.csv or label CSV (also a box whose class is not one of DRONE, AIRPLANE, BIRD, HELICOPTER), a clip
/// named in `clips` that is not listed, or a video that cannot be read.
HalmstadImportSummary import_halmstad(const HalmstadImportOptions& options,
                                      const std::function<void(const std::string&)>& log = {},
                                      const std::function<void(size_t, size_t)>& progress = {});

}  // namespace wingman::training
