// SPDX-License-Identifier: MIT
// `wingman predict`: detector on image files -> YOLO-format text files (and drawn images).
#include "wingman/tools/predict.hpp"

#include <fmt/format.h>
#include <wingman/common/detection_class.hpp>
#include <wingman/common/progress.hpp>
#include <wingman/detector/box.hpp>
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/input_size.hpp>
#include <wingman/detector/model_loader.hpp>
#include <wingman/detector/sized_detector.hpp>

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <optional>
#include <set>

namespace wingman::tools {

namespace fs = std::filesystem;

namespace {

bool is_image(const fs::path& p) {
  static const std::set<std::string> kExt = {".jpg", ".jpeg", ".png", ".bmp", ".tif", ".tiff", ".ppm", ".pgm"};
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return kExt.count(ext) > 0;
}

}  // namespace

std::string prediction_line(const detector::Box& b, double image_width, double image_height) {
  return fmt::format("{} {:.6f} {:.6f} {:.6f} {:.6f} {:.6f}\n", b.class_id, b.cx / image_width, b.cy / image_height,
                     b.w / image_width, b.h / image_height, b.confidence);
}

int run_predict(const PredictOptions& options, std::ostream& out, std::ostream& err) {
  const std::string prefix = "wingman predict: error: ";
  const std::vector<std::string> problems = options.detection.validate();
  if (!problems.empty()) {
    for (const auto& p : problems) err << prefix << p << "\n";
    return 2;
  }
  if (options.weights.empty()) {
    err << prefix << "--weights is required\n";
    return 2;
  }
  if (options.backend != "cpu" && options.backend != "opencl" && options.backend != "auto") {
    err << prefix << fmt::format("--backend = '{}': must be auto, opencl or cpu", options.backend) << "\n";
    return 2;
  }
  std::string size_error;
  const std::optional<detector::InputSize> input_size = detector::InputSize::parse(options.input_size, &size_error);
  if (!input_size) {
    err << prefix << "--input-size = " << size_error << "\n";
    return 2;
  }
  std::vector<fs::path> images;
  for (const std::string& in : options.inputs) {
    std::error_code ec;
    if (fs::is_directory(in, ec)) {
      std::vector<fs::path> found;
      for (const auto& e : fs::directory_iterator(in, ec))
        if (e.is_regular_file() && is_image(e.path())) found.push_back(e.path());
      std::sort(found.begin(), found.end());
      images.insert(images.end(), found.begin(), found.end());
    } else if (fs::is_regular_file(in, ec)) {
      images.emplace_back(in);
    } else {
      err << prefix << fmt::format("input '{}': no such file or folder", in) << "\n";
      return 2;
    }
  }
  if (images.empty()) {
    err << prefix << "no input images\n";
    return 2;
  }

  std::unique_ptr<detector::SizedDetector> pipeline;
  try {
    const int batch = options.detection.zoom_in ? std::min(8, options.detection.max_detections) : 1;
    // Kept by the pipeline and called again when an image of another aspect needs a new network: it must own what it
    // uses from this scope (batch by value; it once read a dangling `batch`, e.g. -501724864, issue #34).
    auto make_backend = [&options, &err, batch](const detector::DarknetModel& sized) {
      std::string why;
      auto backend = detector::make_backend(options.backend, sized, detector::OpenClOptions{}, batch, &why,
                                            detector::AutoChoice::kRepeatable);
      err << fmt::format("wingman predict: {} (network input {}x{})", why, sized.net.width, sized.net.height) << "\n";
      return backend;
    };
    pipeline = std::make_unique<detector::SizedDetector>(
        options.detection, detector::load_model(options.cfg, options.weights), *input_size, make_backend);
    fs::create_directories(options.out_dir);
  } catch (const std::exception& e) {
    err << prefix << e.what() << "\n";
    return 1;
  }

  int failures = 0;
  common::Progress progress("wingman predict", static_cast<int64_t>(images.size()), "images", &err);
  for (size_t i = 0; i < images.size(); ++i) {
    progress.update(static_cast<int64_t>(i), fmt::format("{} failed", failures));  // before the `continue`s below
    const fs::path& path = images[i];
    const cv::Mat bgr = cv::imread(path.string(), cv::IMREAD_COLOR);
    if (bgr.empty()) {
      err << prefix << fmt::format("{}: cannot read the image", path.string()) << "\n";
      ++failures;
      continue;
    }
    std::vector<detector::Box> boxes;
    try {
      boxes = pipeline->detect(bgr);  // a new image aspect may build a network first (input size auto)
    } catch (const std::exception& e) {
      err << prefix << fmt::format("{}: {}", path.string(), e.what()) << "\n";
      ++failures;
      continue;
    }
    const fs::path txt = fs::path(options.out_dir) / (path.stem().string() + ".txt");
    std::ofstream f(txt);
    const double W = bgr.cols, H = bgr.rows;
    // YOLO labels are normalised to the image: a box past the frame is written as its visible part.
    for (const detector::Box& b : detector::clip_to_image(boxes, static_cast<float>(W), static_cast<float>(H)))
      f << prediction_line(b, W, H);
    f.close();
    if (!f) {
      err << prefix << fmt::format("{}: cannot write", txt.string()) << "\n";
      ++failures;
      continue;
    }
    if (options.draw) {
      cv::Mat drawn = bgr.clone();
      for (const detector::Box& b : boxes) {
        const cv::Point p0(cvRound(b.cx - b.w / 2), cvRound(b.cy - b.h / 2));
        const cv::Point p1(cvRound(b.cx + b.w / 2), cvRound(b.cy + b.h / 2));
        const cv::Scalar colour = b.pass != detector::Pass::kSingle ? cv::Scalar(0, 255, 0) : cv::Scalar(0, 0, 255);
        cv::rectangle(drawn, p0, p1, colour, 2);
        cv::putText(drawn, fmt::format("{} {:.2f}", common::detection_class_name(b.class_id), b.confidence),
                    p0 + cv::Point(0, -4), cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1);
      }
      const fs::path jpg = fs::path(options.out_dir) / (path.stem().string() + ".pred.jpg");
      if (!cv::imwrite(jpg.string(), drawn)) {
        err << prefix << fmt::format("{}: cannot write", jpg.string()) << "\n";
        ++failures;
      }
    }
    out << fmt::format("{}: {} detection(s) -> {}", path.string(), boxes.size(), txt.string()) << "\n";
  }
  progress.update(static_cast<int64_t>(images.size()), fmt::format("{} failed", failures));
  progress.finish();
  return failures == 0 ? 0 : 1;
}

}  // namespace wingman::tools
