// SPDX-License-Identifier: MIT
// `wingman model derive-cfg`: a .cfg variant with the original's lines kept, checked with the detector's parser.
#include "wingman/tools/cfg_derive.hpp"

#include <wingman/detector/darknet_cfg.hpp>

#include <fmt/format.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace wingman::tools {

namespace {

namespace fs = std::filesystem;

std::string trim(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r") - b + 1);
}

/// A .cfg as lines, each knowing its section (the [name] header above it) and, for key=value lines, its key.
struct CfgLines {
  struct Line {
    std::string text;
    std::string section;  // "net", "convolutional", ... ("" before the first header)
    int section_index = -1;
    std::string key;  // "" for headers, comments and blank lines
    bool header = false;
  };
  std::vector<Line> lines;
  bool trailing_newline = true;

  explicit CfgLines(const std::string& text) {
    std::string section;
    int index = -1;
    size_t start = 0;
    while (start < text.size()) {
      size_t end = text.find('\n', start);
      const bool last = end == std::string::npos;
      if (last) end = text.size();
      Line l;
      l.text = text.substr(start, end - start);
      const std::string t = trim(l.text);
      if (t.size() >= 2 && t.front() == '[' && t.back() == ']') {
        section = t.substr(1, t.size() - 2);
        ++index;
        l.header = true;
      } else if (!t.empty() && t[0] != '#' && t[0] != ';') {
        if (const size_t eq = t.find('='); eq != std::string::npos) l.key = trim(t.substr(0, eq));
      }
      l.section = section;
      l.section_index = index;
      lines.push_back(std::move(l));
      if (last) trailing_newline = false;
      start = end + 1;
    }
  }

  static bool is_net(const std::string& section) { return section == "net" || section == "network"; }

  /// Sets `key` to `value` in every section that `in_section` accepts: its key=value lines rewritten; a section
  /// without the key gets it right after its header. Returns the number of sections changed.
  template <class Pred>
  int set(const std::string& key, const std::string& value, Pred in_section) {
    int changed = 0;
    std::vector<Line> result;
    for (size_t i = 0; i < lines.size(); ++i) {
      const Line& l = lines[i];
      if (l.header && in_section(l.section)) {
        result.push_back(l);
        bool has = false;
        for (size_t j = i + 1; j < lines.size() && lines[j].section_index == l.section_index; ++j)
          has = has || lines[j].key == key;
        if (!has) result.push_back(Line{key + "=" + value, l.section, l.section_index, key, false});
        ++changed;
        continue;
      }
      if (l.key == key && in_section(l.section)) {
        Line copy = l;
        copy.text = key + "=" + value;
        result.push_back(copy);
        continue;
      }
      result.push_back(l);
    }
    lines = std::move(result);
    return changed;
  }

  /// Keeps the lines up to the `heads`-th [yolo] section and drops the rest from the comment lines directly above
  /// the next section on. Returns the [yolo] sections found (all of them when there are fewer than `heads`).
  int keep_heads(int heads) {
    int seen = 0;
    int cut_section = -1;
    for (const Line& l : lines) {
      if (!l.header) continue;
      if (seen == heads) {
        cut_section = l.section_index;
        break;
      }
      if (l.section == "yolo") ++seen;
    }
    if (cut_section < 0) return seen;
    size_t cut = 0;
    while (!(lines[cut].header && lines[cut].section_index == cut_section)) ++cut;
    while (cut > 0 && trim(lines[cut - 1].text).rfind('#', 0) == 0) --cut;  // its comment block goes with it
    lines.resize(cut);
    trailing_newline = true;
    return seen;
  }

  std::string text() const {
    std::string s;
    for (size_t i = 0; i < lines.size(); ++i) {
      s += lines[i].text;
      if (i + 1 < lines.size() || trailing_newline) s += '\n';
    }
    return s;
  }
};

}  // namespace

std::string derive_cfg_text(const std::string& cfg_text, const std::string& source_name, const CfgDerivation& d) {
  if (d.heads < 0) throw std::invalid_argument(fmt::format("--heads {}: expected 0 (all) or more", d.heads));
  if (d.anchors.size() % 2 != 0 || (!d.anchors.empty() && d.anchors.size() < 2))
    throw std::invalid_argument(fmt::format("--anchors: expected w,h pairs, got {} numbers", d.anchors.size()));
  for (const int a : d.anchors)
    if (a <= 0) throw std::invalid_argument(fmt::format("--anchors: {}: expected sizes > 0 (pixels)", a));
  if (d.width < 0 || d.height < 0 || (d.width > 0) != (d.height > 0))
    throw std::invalid_argument(fmt::format("--input {}x{}: expected WIDTHxHEIGHT, both > 0", d.width, d.height));
  if (!d.iou_loss.empty() && d.iou_loss != "mse" && d.iou_loss != "giou" && d.iou_loss != "diou" &&
      d.iou_loss != "ciou")
    throw std::invalid_argument(fmt::format("--iou-loss '{}': expected mse, giou, diou or ciou", d.iou_loss));
  if (!d.iou_normalizer.empty()) {
    char* end = nullptr;
    const double v = std::strtod(d.iou_normalizer.c_str(), &end);
    if (end == d.iou_normalizer.c_str() || *end != '\0' || !(v > 0.0))
      throw std::invalid_argument(fmt::format("--iou-normalizer '{}': expected a number > 0", d.iou_normalizer));
  }
  // The input must be a .cfg the detector reads.
  detector::parse_darknet_cfg_string(cfg_text, source_name);

  CfgLines cfg(cfg_text);
  const auto yolo = [](const std::string& s) { return s == "yolo"; };
  if (d.heads > 0) {
    const int found = cfg.keep_heads(d.heads);
    if (found < d.heads)
      throw std::invalid_argument(fmt::format("--heads {}: {} has {} [yolo] heads", d.heads, source_name, found));
  }
  if (!d.anchors.empty()) {
    std::string value;
    for (size_t i = 0; i < d.anchors.size(); i += 2)
      value += fmt::format("{}{},{}", i == 0 ? "" : ", ", d.anchors[i], d.anchors[i + 1]);
    cfg.set("anchors", value, yolo);
    cfg.set("num", std::to_string(d.anchors.size() / 2), yolo);
  }
  if (d.width > 0) {
    cfg.set("width", std::to_string(d.width), CfgLines::is_net);
    cfg.set("height", std::to_string(d.height), CfgLines::is_net);
  }
  if (!d.iou_normalizer.empty()) cfg.set("iou_normalizer", d.iou_normalizer, yolo);
  if (!d.iou_loss.empty()) cfg.set("iou_loss", d.iou_loss, yolo);  // inserted above iou_normalizer

  const std::string text = cfg.text();
  const detector::DarknetModel model = detector::parse_darknet_cfg_string(text, source_name + " (derived)");
  if (d.heads > 0 && static_cast<int>(model.heads().size()) != d.heads)
    throw std::invalid_argument(
        fmt::format("--heads {}: the derived .cfg has {} heads", d.heads, model.heads().size()));
  return text;
}

void derive_cfg_file(const std::string& in, const std::string& out, const CfgDerivation& d) {
  std::ifstream f(in, std::ios::binary);
  if (!f) throw std::runtime_error(fmt::format("{}: cannot read the .cfg", in));
  std::stringstream ss;
  ss << f.rdbuf();
  const std::string text = derive_cfg_text(ss.str(), in, d);
  if (const fs::path parent = fs::path(out).parent_path(); !parent.empty()) fs::create_directories(parent);
  std::ofstream o(out, std::ios::binary);
  o << text;
  if (!o.flush()) throw std::runtime_error(fmt::format("{}: cannot write the .cfg", out));
}

}  // namespace wingman::tools
