// SPDX-License-Identifier: MIT
// YOLO-layout dataset reader and writer.
#include "wingman/training/yolo_dataset.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

namespace wingman::training {

namespace fs = std::filesystem;

namespace {

bool is_image_file(const fs::path& p) {
  static const std::set<std::string> kExt = {".jpg", ".jpeg", ".png", ".bmp"};
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  return kExt.count(ext) > 0;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw DatasetError(fmt::format("{}: cannot read the file", path));
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

std::vector<std::string> split_fields(const std::string& line) {
  std::vector<std::string> out;
  std::istringstream in(line);
  std::string f;
  while (in >> f) out.push_back(f);
  return out;
}

/// Parses lines of 5 (labels) or 6 (predictions) fields.
template <class Emit>
void parse_lines(const std::string& text, int classes, const std::string& source, size_t fields, Emit emit) {
  static const char* kNames[] = {"class", "cx", "cy", "w", "h", "confidence"};
  std::istringstream in(text);
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const std::vector<std::string> f = split_fields(line);
    if (f.empty()) continue;
    auto fail = [&](const std::string& what) {
      throw DatasetError(fmt::format("{}:{}: {} (line '{}')", source, line_no, what, line));
    };
    if (f.size() != fields)
      fail(fmt::format("expected {} fields '{}', got {}", fields,
                       fields == 5 ? "class cx cy w h" : "class cx cy w h confidence", f.size()));
    char* end = nullptr;
    errno = 0;
    const long cls = std::strtol(f[0].c_str(), &end, 10);
    if (errno != 0 || end == f[0].c_str() || *end != '\0')
      fail(fmt::format("field class = '{}': expected an integer", f[0]));
    if (cls < 0 || cls >= classes)
      fail(fmt::format("field class = {}: expected 0..{} ({} classes)", cls, classes - 1, classes));
    float v[5] = {0, 0, 0, 0, 0};
    for (size_t k = 1; k < fields; ++k) {
      end = nullptr;
      const float x = std::strtof(f[k].c_str(), &end);
      if (end == f[k].c_str() || *end != '\0' || !std::isfinite(x))
        fail(fmt::format("field {} = '{}': expected a number", kNames[k], f[k]));
      v[k - 1] = x;
    }
    for (int k = 0; k < 2; ++k)
      if (v[k] < 0.f || v[k] > 1.f) fail(fmt::format("field {} = {}: expected 0..1 (normalised)", kNames[k + 1], v[k]));
    for (int k = 2; k < 4; ++k)
      if (v[k] <= 0.f || v[k] > 1.f)
        fail(fmt::format("field {} = {}: expected 0 < {} <= 1 (normalised)", kNames[k + 1], v[k], kNames[k + 1]));
    if (fields == 6 && (v[4] < 0.f || v[4] > 1.f)) fail(fmt::format("field confidence = {}: expected 0..1", v[4]));
    emit(LabeledBox{static_cast<int>(cls), v[0], v[1], v[2], v[3]}, v[4]);
  }
}

void collect_images(const fs::path& dir, std::vector<std::string>& out) {
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(dir, fs::directory_options::follow_directory_symlink, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (ec) break;
    if (it->is_regular_file(ec) && is_image_file(it->path())) out.push_back(it->path().string());
  }
  if (ec) throw DatasetError(fmt::format("{}: cannot list the folder: {}", dir.string(), ec.message()));
}

/// One `train:`/`val:` entry: a folder, or a .txt list of images (paths relative to the root).
void add_entry(const fs::path& root, const std::string& entry, const std::string& where,
               std::vector<std::string>& out) {
  fs::path p(entry);
  if (p.is_relative()) p = root / p;
  std::error_code ec;
  if (fs::is_directory(p, ec)) {
    collect_images(p, out);
  } else if (fs::is_regular_file(p, ec) && p.extension() == ".txt") {
    std::istringstream in(read_text(p.string()));
    std::string line;
    int line_no = 0;
    while (std::getline(in, line)) {
      ++line_no;
      const auto f = split_fields(line);
      if (f.empty()) continue;
      fs::path img(f[0]);
      if (img.is_relative()) img = root / img;
      if (!fs::is_regular_file(img, ec))
        throw DatasetError(fmt::format("{}:{}: image '{}' does not exist", p.string(), line_no, img.string()));
      out.push_back(img.string());
    }
  } else {
    throw DatasetError(
        fmt::format("{}: '{}' ({}) is neither a folder of images nor a .txt list", where, entry, p.string()));
  }
}

}  // namespace

size_t YoloDataset::box_count() const {
  size_t n = 0;
  for (const auto& i : images) n += i.boxes.size();
  return n;
}

size_t YoloDataset::negative_count() const {
  size_t n = 0;
  for (const auto& i : images) n += i.boxes.empty() ? 1 : 0;
  return n;
}

std::vector<size_t> evenly_spaced(size_t count, size_t max) {
  std::vector<size_t> out;
  const size_t n = max == 0 || max >= count ? count : max;
  out.reserve(n);
  for (size_t k = 0; k < n; ++k) out.push_back(n == count ? k : k * count / n);
  return out;
}

std::vector<LabeledBox> parse_yolo_labels(const std::string& text, int classes, const std::string& source) {
  std::vector<LabeledBox> out;
  parse_lines(text, classes, source, 5, [&](const LabeledBox& b, float) { out.push_back(b); });
  return out;
}

std::vector<LabeledBox> read_yolo_labels(const std::string& path, int classes) {
  return parse_yolo_labels(read_text(path), classes, path);
}

std::vector<PredictedBox> read_yolo_predictions(const std::string& path, int classes) {
  std::vector<PredictedBox> out;
  parse_lines(read_text(path), classes, path, 6, [&](const LabeledBox& b, float c) { out.push_back({b, c}); });
  return out;
}

std::string label_path_for(const std::string& image_path) {
  fs::path p(image_path);
  std::vector<fs::path> parts(p.begin(), p.end());
  if (parts.empty()) throw DatasetError("label_path_for: empty image path");
  for (size_t i = parts.size() - 1; i-- > 0;) {  // the last folder named images (not the file itself)
    if (parts[i] == "images") {
      fs::path out;
      for (size_t k = 0; k < parts.size(); ++k) out /= (k == i ? fs::path("labels") : parts[k]);
      out.replace_extension(".txt");
      return out.string();
    }
  }
  throw DatasetError(
      fmt::format("{}: the image is not under an 'images' folder, so it has no labels/ twin", image_path));
}

YoloDataset load_yolo_dataset(const std::string& spec, const std::string& split) {
  YoloDataset ds;
  ds.source = spec;
  ds.split = split;
  std::vector<std::string> paths;
  std::error_code ec;
  const fs::path spec_path(spec);
  const std::string ext = spec_path.extension().string();
  if (ext == ".yaml" || ext == ".yml") {
    YAML::Node root;
    try {
      root = YAML::LoadFile(spec);
    } catch (const YAML::BadFile&) {
      throw DatasetError(fmt::format("{}: cannot read the file", spec));
    } catch (const YAML::Exception& e) {
      throw DatasetError(fmt::format("{}:{}: not valid YAML: {}", spec, e.mark.line + 1, e.msg));
    }
    if (!root.IsMap()) throw DatasetError(fmt::format("{}: expected a mapping (path, train, val, nc, names)", spec));
    fs::path base = spec_path.parent_path();
    try {
      if (root["path"]) {
        fs::path p(root["path"].as<std::string>());
        base = p.is_relative() ? base / p : p;
      }
      if (root["names"]) {
        const YAML::Node names = root["names"];
        if (names.IsSequence()) {
          for (const auto& n : names) ds.class_names.push_back(n.as<std::string>());
        } else if (names.IsMap()) {
          std::vector<std::pair<int, std::string>> kv;
          for (const auto& n : names) kv.emplace_back(n.first.as<int>(), n.second.as<std::string>());
          std::sort(kv.begin(), kv.end());
          for (size_t i = 0; i < kv.size(); ++i) {
            if (kv[i].first != static_cast<int>(i))
              throw DatasetError(
                  fmt::format("{}: key 'names': indices must be 0..{}, found {}", spec, kv.size() - 1, kv[i].first));
            ds.class_names.push_back(kv[i].second);
          }
        } else {
          throw DatasetError(fmt::format("{}: key 'names': expected a list or a map of index: name", spec));
        }
      }
      if (root["nc"]) {
        const int nc = root["nc"].as<int>();
        if (nc < 1) throw DatasetError(fmt::format("{}: key 'nc' = {}: must be >= 1", spec, nc));
        if (ds.class_names.empty())
          for (int i = 0; i < nc; ++i) ds.class_names.push_back(fmt::format("class{}", i));
        else if (static_cast<int>(ds.class_names.size()) != nc)
          throw DatasetError(
              fmt::format("{}: key 'nc' = {} but 'names' has {} entries", spec, nc, ds.class_names.size()));
      }
      if (ds.class_names.empty()) ds.class_names = {"drone"};
      if (split.empty() || !root[split])
        throw DatasetError(fmt::format("{}: no key '{}' (the split to read; the file has train/val/test keys)", spec,
                                       split.empty() ? "<empty split>" : split));
      const YAML::Node entry = root[split];
      const std::string where = fmt::format("{}: key '{}'", spec, split);
      if (entry.IsSequence()) {
        for (const auto& e : entry) add_entry(base, e.as<std::string>(), where, paths);
      } else {
        add_entry(base, entry.as<std::string>(), where, paths);
      }
    } catch (const YAML::Exception& e) {
      throw DatasetError(fmt::format("{}:{}: {}", spec, e.mark.line + 1, e.msg));
    }
  } else if (fs::is_directory(spec_path, ec)) {
    ds.class_names = {"drone"};
    fs::path images;
    if (split.empty()) {
      images = spec_path / "images";
    } else if (fs::is_directory(spec_path / "images" / split, ec)) {
      images = spec_path / "images" / split;
    } else {
      images = spec_path / split / "images";
    }
    if (!fs::is_directory(images, ec))
      throw DatasetError(fmt::format(
          "{}: no images folder for split '{}' (looked for {})", spec, split,
          split.empty() ? (spec_path / "images").string()
                        : (spec_path / "images" / split).string() + " and " + (spec_path / split / "images").string()));
    collect_images(images, paths);
  } else {
    throw DatasetError(fmt::format("{}: not a data.yaml nor a folder", spec));
  }
  std::sort(paths.begin(), paths.end());
  paths.erase(std::unique(paths.begin(), paths.end()), paths.end());
  if (paths.empty()) throw DatasetError(fmt::format("{}: split '{}' has no images", spec, split));
  const int classes = static_cast<int>(ds.class_names.size());
  ds.images.reserve(paths.size());
  for (const std::string& p : paths) {
    DatasetImage img;
    img.image_path = p;
    img.label_path = label_path_for(p);
    img.has_label_file = fs::is_regular_file(img.label_path, ec);
    if (img.has_label_file) img.boxes = read_yolo_labels(img.label_path, classes);
    ds.images.push_back(std::move(img));
  }
  return ds;
}

void write_yolo_labels(const std::string& path, const std::vector<LabeledBox>& boxes) {
  std::error_code ec;
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) fs::create_directories(parent, ec);
  std::ofstream f(path);
  for (const LabeledBox& b : boxes) f << fmt::format("{} {:.6f} {:.6f} {:.6f} {:.6f}\n", b.cls, b.cx, b.cy, b.w, b.h);
  f.close();
  if (!f) throw DatasetError(fmt::format("{}: cannot write the label file", path));
}

void write_data_yaml(const std::string& path, const std::vector<std::string>& class_names,
                     const std::vector<std::string>& comments) {
  std::ofstream f(path);
  for (const std::string& c : comments) f << "# " << c << "\n";
  // No `path:` key: readers take the data.yaml's own folder as the root (ours, and Ultralytics, which resolves a
  // relative `path` against its datasets folder, not this file's), so the set works from anywhere and can be moved.
  f << "train: images/train\nval: images/val\n";
  f << "nc: " << class_names.size() << "\nnames: [";
  for (size_t i = 0; i < class_names.size(); ++i) f << (i ? ", " : "") << class_names[i];
  f << "]\n";
  f.close();
  if (!f) throw DatasetError(fmt::format("{}: cannot write data.yaml", path));
}

}  // namespace wingman::training
