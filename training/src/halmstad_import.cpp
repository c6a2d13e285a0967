// SPDX-License-Identifier: MIT
// Halmstad dataset -> YOLO layout: frame sampling, box conversion and tightening, split by clip.
#include "wingman/training/halmstad_import.hpp"

#include "wingman/training/halmstad_labels.hpp"

#include "wingman/training/seeded_random.hpp"
#include "wingman/training/yolo_dataset.hpp"

#include <wingman/common/detection_class.hpp>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/videoio.hpp>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace wingman::training {

namespace fs = std::filesystem;

std::vector<std::string> HalmstadImportOptions::validate() const {
  std::vector<std::string> p;
  if (root.empty()) p.push_back("root is empty: the Halmstad dataset folder is required");
  if (out_dir.empty()) p.push_back("out_dir is empty");
  if (frame_step < 1) p.push_back(fmt::format("frame_step = {}: must be >= 1", frame_step));
  if (negative_frame_step < 1) p.push_back(fmt::format("negative_frame_step = {}: must be >= 1", negative_frame_step));
  if (max_frames_per_clip < 0) p.push_back(fmt::format("max_frames_per_clip = {}: must be >= 0", max_frames_per_clip));
  if (!(val_fraction >= 0.0 && val_fraction <= 1.0))
    p.push_back(fmt::format("val_fraction = {}: must be in 0..1", val_fraction));
  if (jpeg_quality < 1 || jpeg_quality > 100)
    p.push_back(fmt::format("jpeg_quality = {}: must be in 1..100", jpeg_quality));
  if (distractor_classes && !negatives)
    p.push_back("distractor_classes is set but negatives is not: the distractor classes come from the non-drone clips");
  for (const auto& s : tightening.validate()) p.push_back(s);
  return p;
}

std::string HalmstadImportSummary::one_line() const {
  return fmt::format(
      "{} train clips / {} images, {} val clips / {} images; {} drone boxes, {} airplane/bird/helicopter boxes ({} "
      "of all boxes tightened, mean area x{:.2f}), {} negative images",
      train_clips.size(), train_images, val_clips.size(), val_images, boxes, distractor_boxes, tightened,
      mean_area_ratio, negative_images);
}

std::string HalmstadImportSummary::report() const {
  std::string s = one_line() + "\ntrain clips:";
  for (const auto& c : train_clips) s += " " + c;
  s += "\nval clips:";
  for (const auto& c : val_clips) s += " " + c;
  return s + "\n";
}

namespace {

/// FNV-1a: a string hash that is the same on every platform (std::hash is not).
uint64_t fnv1a(const std::string& s) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) h = (h ^ c) * 1099511628211ull;
  return h;
}

struct Clip {
  std::string name, cls, distance;
  int frames = 0;
};

std::vector<Clip> read_clips(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw DatasetError(fmt::format("{}: cannot read the clip list", path));
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> header = split_csv_line(line);
  if (header.size() < 5 || header[0] != "clip" || header[1] != "class" || header[3] != "distance_bin" ||
      header[4] != "frames")
    throw DatasetError(
        fmt::format("{}:1: expected the header 'clip,class,drone_type,distance_bin,frames,...', got '{}'", path, line));
  std::vector<Clip> clips;
  int line_no = 1;
  while (std::getline(in, line)) {
    ++line_no;
    if (line.empty() || line == "\r") continue;
    const std::vector<std::string> f = split_csv_line(line);
    if (f.size() < 5)
      throw DatasetError(fmt::format("{}:{}: expected at least 5 fields, got {}", path, line_no, f.size()));
    Clip c{f[0], f[1], f[3], std::atoi(f[4].c_str())};
    if (c.name.empty() || c.cls.empty()) throw DatasetError(fmt::format("{}:{}: empty clip or class", path, line_no));
    clips.push_back(c);
  }
  return clips;
}

}  // namespace

HalmstadImportSummary import_halmstad(const HalmstadImportOptions& o,
                                      const std::function<void(const std::string&)>& log,
                                      const std::function<void(size_t, size_t)>& progress) {
  const std::vector<std::string> problems = o.validate();
  if (!problems.empty()) {
    std::string msg = "import_halmstad: invalid options:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw std::invalid_argument(msg);
  }
  const fs::path root(o.root);
  std::vector<Clip> clips = read_clips((root / "clips.csv").string());
  if (!o.clips.empty()) {
    std::vector<Clip> chosen;
    for (const std::string& name : o.clips) {
      const auto it = std::find_if(clips.begin(), clips.end(), [&](const Clip& c) { return c.name == name; });
      if (it == clips.end())
        throw DatasetError(fmt::format("{}: clip '{}' is not listed", (root / "clips.csv").string(), name));
      chosen.push_back(*it);
    }
    clips = chosen;
  }
  const std::set<std::string> excluded(o.exclude.begin(), o.exclude.end());
  clips.erase(
      std::remove_if(clips.begin(), clips.end(),
                     [&](const Clip& c) { return excluded.count(c.name) > 0 || (!o.negatives && c.cls != "DRONE"); }),
      clips.end());
  std::sort(clips.begin(), clips.end(), [](const Clip& a, const Clip& b) { return a.name < b.name; });

  // Split by clip, per (class, distance bin) group.
  std::map<std::pair<std::string, std::string>, std::vector<size_t>> groups;
  for (size_t i = 0; i < clips.size(); ++i) groups[{clips[i].cls, clips[i].distance}].push_back(i);
  std::vector<bool> is_val(clips.size(), false);
  for (auto& [key, members] : groups) {
    SeededRandom rng(mix_seed(o.seed, fnv1a(key.first + "/" + key.second)));
    for (size_t i = members.size(); i > 1; --i) std::swap(members[i - 1], members[rng.below(i)]);
    const size_t n_val = static_cast<size_t>(std::lround(o.val_fraction * static_cast<double>(members.size())));
    for (size_t k = 0; k < n_val && k < members.size(); ++k) is_val[members[k]] = true;
  }

  HalmstadImportSummary summary;
  double ratio_sum = 0.0;
  const fs::path out(o.out_dir);
  std::ofstream splits;
  fs::create_directories(out);
  splits.open((out / "splits.csv").string());
  splits << "clip,class,distance_bin,split,images\n";
  const std::vector<int> jpeg = {cv::IMWRITE_JPEG_QUALITY, o.jpeg_quality};
  for (size_t ci = 0; ci < clips.size(); ++ci) {
    const Clip& clip = clips[ci];
    const bool drone = clip.cls == "DRONE";
    const std::string split = is_val[ci] ? "val" : "train";
    (is_val[ci] ? summary.val_clips : summary.train_clips).push_back(clip.name);
    std::map<int, std::vector<HalmstadLabelBox>> boxes;
    if (drone || o.distractor_classes) boxes = read_halmstad_labels((root / "labels" / (clip.name + ".csv")).string());
    const std::string video = (root / "videos" / (clip.name + ".mp4")).string();
    cv::VideoCapture cap(video, cv::CAP_FFMPEG);  // MP4 clips: FFmpeg, no fallback to other backends
    if (!cap.isOpened()) throw DatasetError(fmt::format("{}: cannot open the video", video));
    const int step = drone ? o.frame_step : o.negative_frame_step;
    int written = 0, clip_boxes = 0, clip_distractors = 0, clip_tight = 0;
    cv::Mat frame;
    for (int k = 0;; ++k) {
      if (o.max_frames_per_clip > 0 && written >= o.max_frames_per_clip) break;
      if (k % step != 0) {
        if (!cap.grab()) break;
        continue;
      }
      if (!cap.read(frame) || frame.empty()) break;
      std::vector<LabeledBox> labels;
      {
        const auto it = boxes.find(k);
        if (it != boxes.end())
          for (const HalmstadLabelBox& label : it->second) {
            const cv::Rect2d& loose = label.rect;
            cv::Rect2d b = loose;
            if (o.tighten) {
              const TightenResult t = tighten_box(frame, loose, o.tightening);
              if (t.tightened) {
                ++clip_tight;
                ratio_sum += t.box.area() / loose.area();
                b = t.box;
              }
            }
            // Clip to the image and normalise.
            const double x0 = std::clamp(b.x, 0.0, static_cast<double>(frame.cols));
            const double y0 = std::clamp(b.y, 0.0, static_cast<double>(frame.rows));
            const double x1 = std::clamp(b.x + b.width, 0.0, static_cast<double>(frame.cols));
            const double y1 = std::clamp(b.y + b.height, 0.0, static_cast<double>(frame.rows));
            if (x1 - x0 < 1.0 || y1 - y0 < 1.0) continue;
            labels.push_back({label.cls, static_cast<float>(0.5 * (x0 + x1) / frame.cols),
                              static_cast<float>(0.5 * (y0 + y1) / frame.rows),
                              static_cast<float>((x1 - x0) / frame.cols), static_cast<float>((y1 - y0) / frame.rows)});
            ++(label.cls == 0 ? clip_boxes : clip_distractors);
          }
      }
      const std::string stem = fmt::format("{}_{:04d}", clip.name, k);
      const fs::path image = out / "images" / split / (stem + ".jpg");
      fs::create_directories(image.parent_path());
      if (!cv::imwrite(image.string(), frame, jpeg))
        throw DatasetError(fmt::format("{}: cannot write the image", image.string()));
      write_yolo_labels((out / "labels" / split / (stem + ".txt")).string(), labels);
      ++written;
      if (labels.empty()) ++summary.negative_images;
      (is_val[ci] ? summary.val_images : summary.train_images) += 1;
    }
    if (written == 0) throw DatasetError(fmt::format("{}: no frame could be read", video));
    summary.boxes += clip_boxes;
    summary.distractor_boxes += clip_distractors;
    summary.tightened += clip_tight;
    splits << fmt::format("{},{},{},{},{}\n", clip.name, clip.cls, clip.distance, split, written);
    if (log)
      log(fmt::format("{} ({} {}): {} -> {} images, {} boxes, {} tightened", clip.name, clip.cls, clip.distance, split,
                      written, clip_boxes + clip_distractors, clip_tight));
    if (progress) progress(ci + 1, clips.size());
  }
  summary.mean_area_ratio = summary.tightened > 0 ? ratio_sum / static_cast<double>(summary.tightened) : 0.0;
  splits.close();
  if (!splits) throw DatasetError(fmt::format("{}: cannot write", (out / "splits.csv").string()));
  // The Halmstad label classes' order (halmstad_labels.hpp) is the detector's: common::kDetectionClassNames.
  const std::vector<std::string> names =
      o.distractor_classes
          ? std::vector<std::string>(common::kDetectionClassNames.begin(), common::kDetectionClassNames.end())
          : std::vector<std::string>{common::kDetectionClassNames[common::kDroneClassId]};
  write_data_yaml((out / "data.yaml").string(), names,
                  {"Halmstad drone detection dataset (CC0-1.0; Svanstrom et al., Data in Brief 39, 2021), imported by "
                   "wingman import-halmstad",
                   fmt::format("frame_step {}, negative_frame_step {}, val_fraction {}, seed {}, tighten {}, "
                               "distractor_classes {}",
                               o.frame_step, o.negative_frame_step, o.val_fraction, o.seed, o.tighten ? "on" : "off",
                               o.distractor_classes ? "on" : "off"),
                   "split by clip: see splits.csv"});
  return summary;
}

}  // namespace wingman::training
