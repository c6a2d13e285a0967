// SPDX-License-Identifier: MIT
// Fuzz target: the YOLO label and dataset readers of training/ (the libtorch-free part), as `wingman val` and the
// trainer read them. The input is records (fuzz_support.hpp); by the first selector % 3:
//   0: each record's payload is a label file (parse_yolo_labels, classes = selector % 4 + 1);
//   1: each payload is a prediction file (read_yolo_predictions, from a file);
//   2: the first payload is a data.yaml, the second the label file of the one image of a small dataset folder
//      beside it (images/val/a.png, images/train/b.png), and load_yolo_dataset(data.yaml, "val" or "train") reads
//      them. Anything wrong must be a DatasetError.
#include "fuzz_support.hpp"

#include <wingman/training/yolo_dataset.hpp>

#include <opencv2/imgcodecs.hpp>

#include <filesystem>

namespace {

namespace fs = std::filesystem;

/// A dataset folder in $TMPDIR for this process: images/{val,train}/*.png and their labels folders.
struct DatasetDir {
  fs::path root;
  DatasetDir() {
    const char* dir = std::getenv("TMPDIR");
    root = fs::path(dir && *dir ? dir : "/tmp") / ("wingman_fuzz_dataset_" + std::to_string(getpid()));
    for (const char* split : {"val", "train"}) {
      fs::create_directories(root / "images" / split);
      fs::create_directories(root / "labels" / split);
    }
    const cv::Mat image(8, 8, CV_8UC3, cv::Scalar(10, 20, 30));
    cv::imwrite((root / "images" / "val" / "a.png").string(), image);
    cv::imwrite((root / "images" / "train" / "b.png").string(), image);
  }
  ~DatasetDir() {
    std::error_code ec;
    fs::remove_all(root, ec);
  }
};

void write(const fs::path& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wingman::training;
  static DatasetDir dataset;
  static wingman::fuzz::TempFile predictions(".txt");
  wingman::fuzz::Records records(data, size);
  uint8_t selector = 0;
  const uint8_t* payload = nullptr;
  size_t n = 0;
  if (!records.next(&selector, &payload, &n)) return 0;
  const int mode = selector % 3;
  if (mode == 2) {
    write(dataset.root / "data.yaml", payload, n);
    const bool val = selector & 4;
    uint8_t unused = 0;
    if (records.next(&unused, &payload, &n))
      write(dataset.root / "labels" / (val ? "val" : "train") / (val ? "a.txt" : "b.txt"), payload, n);
    try {
      const YoloDataset d = load_yolo_dataset((dataset.root / "data.yaml").string(), val ? "val" : "train");
      (void)d;
    } catch (const DatasetError&) {
    }
    return 0;
  }
  for (int i = 0; i < 16; ++i) {
    try {
      if (mode == 0) {
        (void)parse_yolo_labels(std::string(reinterpret_cast<const char*>(payload), n), selector % 4 + 1, "<fuzz>");
      } else {
        (void)read_yolo_predictions(predictions.write(payload, n), selector % 4 + 1);
      }
    } catch (const DatasetError&) {
    }
    if (!records.next(&selector, &payload, &n)) break;
  }
  return 0;
}
