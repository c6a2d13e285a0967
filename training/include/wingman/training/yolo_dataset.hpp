// SPDX-License-Identifier: MIT
// YOLO-layout datasets: images/ and labels/ folders (`class cx cy w h` per line, normalised), data.yaml.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::training {

/// A malformed dataset: what() is one line naming the file (and the line and field where it applies) and
/// what was expected.
class DatasetError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// One labelled box, YOLO convention: centre and size as fractions of the image width / height.
struct LabeledBox {
  int cls = 0;     ///< class index, 0 .. classes - 1 (0 = drone)
  float cx = 0.f;  ///< centre x / image width, 0..1
  float cy = 0.f;  ///< centre y / image height, 0..1
  float w = 0.f;   ///< width / image width, 0 < w <= 1
  float h = 0.f;   ///< height / image height, 0 < h <= 1
};

/// One predicted box as `wingman predict` writes it: a LabeledBox and its confidence.
struct PredictedBox {
  LabeledBox box;
  float confidence = 0.f;  ///< 0..1
};

/// One image of a dataset and its boxes.
struct DatasetImage {
  std::string image_path;
  std::string label_path;       ///< where its labels are (or would be): images/.../x.jpg -> labels/.../x.txt
  bool has_label_file = false;  ///< false: no label file, the image is a negative (no object)
  std::vector<LabeledBox> boxes;
};

/// A split of a dataset.
struct YoloDataset {
  std::string source;                    ///< the data.yaml or folder it was read from (for messages)
  std::string split;                     ///< "train", "val", "test" or "" (a folder without splits)
  std::vector<std::string> class_names;  ///< from data.yaml `names`; {"drone"} for a bare folder
  std::vector<DatasetImage> images;      ///< sorted by image path

  /// Number of boxes over all images.
  size_t box_count() const;
  /// Images without any box (negatives).
  size_t negative_count() const;
};

/// Indices of at most `max` of `count` items spread evenly over them (k * count / max for k < max, so a subset of
/// a clip-sorted split samples every clip); all of them, in order, when max is 0 or >= count.
std::vector<size_t> evenly_spaced(size_t count, size_t max);

/// Parses the text of one label file: one `class cx cy w h` line per box (blank lines allowed).
/// Throws DatasetError "<source>:<line>: ..." naming the field when a line does not have 5 numbers, the
/// class is not an integer in 0..classes-1, cx or cy is outside 0..1, or w or h is outside (0, 1].
std::vector<LabeledBox> parse_yolo_labels(const std::string& text, int classes, const std::string& source);

/// Reads one label file with parse_yolo_labels; throws DatasetError naming the file if it cannot be read.
std::vector<LabeledBox> read_yolo_labels(const std::string& path, int classes);

/// Reads one prediction file of `wingman predict` (`class cx cy w h confidence` per line), with the
/// checks of parse_yolo_labels plus confidence in 0..1. A 5-field line (no confidence) is an error.
std::vector<PredictedBox> read_yolo_predictions(const std::string& path, int classes);

/// The label file of an image: the last `images` folder of its path becomes `labels`, the extension `.txt`
/// (`d/images/train/a.jpg` -> `d/labels/train/a.txt`). Throws DatasetError if the path has no `images`
/// folder.
std::string label_path_for(const std::string& image_path);

/// Reads a dataset split.
///
/// `spec` is either
///  - a data.yaml (Ultralytics layout): optional `path` (root, relative to the yaml's folder), `train`,
///    `val`, `test` (each a folder of images under the root, a .txt file listing image paths, or a list of
///    these), `nc` and `names` (a list, or a map from index to name). Other keys are ignored (tools add
///    their own). `split` must name a key present in the file.
///  - a folder: with `split` non-empty, `<spec>/images/<split>` (or `<spec>/<split>/images`); with `split`
///    empty, `<spec>/images`. One class, "drone".
/// Images are .jpg .jpeg .png .bmp files found recursively, sorted by path. An image whose label file is
/// missing or empty is a negative. Throws DatasetError naming the file (and line and key) for a missing
/// folder or split, a malformed data.yaml, a bad label line, or a split without images.
YoloDataset load_yolo_dataset(const std::string& spec, const std::string& split);

/// Writes `boxes` as a label file (`class cx cy w h`, 6 decimals), creating its folder. An empty vector
/// writes an empty file (a negative). Throws DatasetError naming the file on failure.
void write_yolo_labels(const std::string& path, const std::vector<LabeledBox>& boxes);

/// Writes a data.yaml: `path: .`, `train: images/train`, `val: images/val`, `nc`, `names`, and a comment
/// line per entry of `comments`. Throws DatasetError naming the file on failure.
void write_data_yaml(const std::string& path, const std::vector<std::string>& class_names,
                     const std::vector<std::string>& comments);

}  // namespace wingman::training
