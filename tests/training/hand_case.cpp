// SPDX-License-Identifier: MIT
// The hand-computed detection case as files.
#include "hand_case.hpp"

#include <wingman/training/yolo_dataset.hpp>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace wingman::training {

namespace fs = std::filesystem;

void write_hand_case(const testing::TempDir& dir) {
  for (const char* name : {"a", "b", "c"}) {
    const std::string img = dir.file(fmt::format("images/val/{}.png", name));
    fs::create_directories(fs::path(img).parent_path());
    if (!cv::imwrite(img, cv::Mat(400, 400, CV_8UC3, cv::Scalar(180, 170, 160))))
      throw std::runtime_error("cannot write " + img);
  }
  auto n = [](double px) { return static_cast<float>(px / 400.0); };
  write_yolo_labels(dir.file("labels/val/a.txt"), {{0, n(50), n(50), n(20), n(20)},
                                                   {0, n(150), n(50), n(10), n(10)},
                                                   {1, 0.5f, 0.5f, 0.1f, 0.1f}});  // class 1: not evaluated
  write_yolo_labels(dir.file("labels/val/b.txt"), {{0, n(100), n(100), n(40), n(40)}});
  fs::create_directories(dir.file("pred"));
  auto line = [&](double cx, double cy, double w, double h, double c) {
    return fmt::format("0 {:.6f} {:.6f} {:.6f} {:.6f} {:.6f}\n", n(cx), n(cy), n(w), n(h), c);
  };
  std::ofstream(dir.file("pred/a.txt")) << line(52, 50, 20, 20, 0.9) << line(150, 52, 30, 30, 0.6)
                                        << line(300, 300, 10, 10, 0.3);
  std::ofstream(dir.file("pred/b.txt")) << line(100, 100, 40, 40, 0.1) << line(102, 100, 40, 40, 0.8);
  std::ofstream(dir.file("pred/c.txt")) << line(10, 10, 8, 8, 0.5);
  std::ofstream(dir.file("data.yaml")) << "path: .\nval: images/val\nnames: [drone, bird]\n";
}

}  // namespace wingman::training
