// SPDX-License-Identifier: MIT
// BoxRelation: reading, checking and looking up a model's box-to-sphere ratios.
#include "wingman/localizer/box_relation.hpp"

#include <fmt/format.h>
#include <wingman/common/config.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace wingman::localizer {
namespace {

constexpr const char* kBuiltinSmall = "builtin:wingman-small";

bool all_finite_positive(const std::vector<double>& v) {
  return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x) && x > 0; });
}

bool strictly_increasing(const std::vector<double>& v) {
  for (size_t i = 1; i < v.size(); ++i)
    if (!(v[i] > v[i - 1])) return false;
  return true;
}

/// Bin of x among `edges` (n + 1 edges, n bins), clamped to [0, n - 1].
size_t bin_of(const std::vector<double>& edges, double x) {
  const auto it = std::upper_bound(edges.begin(), edges.end(), x);
  const ptrdiff_t i = (it - edges.begin()) - 1;
  return static_cast<size_t>(std::clamp<ptrdiff_t>(i, 0, static_cast<ptrdiff_t>(edges.size()) - 2));
}

}  // namespace

std::vector<std::string> BoxRelation::Grid::validate(const std::string& prefix) const {
  std::vector<std::string> p;
  const auto vec = [](const std::vector<double>& v) { return fmt::format("[{}]", fmt::join(v, ", ")); };
  if (size_edges.size() < 2 || !all_finite_positive(size_edges) || !strictly_increasing(size_edges))
    p.push_back(fmt::format("{}size_edges = {}: must be >= 2 increasing numbers > 0", prefix, vec(size_edges)));
  if (aspect_edges.size() < 2 || !all_finite_positive(aspect_edges) || !strictly_increasing(aspect_edges))
    p.push_back(fmt::format("{}aspect_edges = {}: must be >= 2 increasing numbers > 0", prefix, vec(aspect_edges)));
  if (!p.empty()) return p;
  const size_t cells = (size_edges.size() - 1) * (aspect_edges.size() - 1);
  const auto table = [&](const char* key, const std::vector<double>& v, bool positive) {
    if (v.size() != cells) {
      p.push_back(fmt::format("{}{}: {} values, expected {} ((size_edges - 1) x (aspect_edges - 1))", prefix, key,
                              v.size(), cells));
    } else if (!std::all_of(v.begin(), v.end(),
                            [&](double x) { return std::isfinite(x) && (positive ? x > 0 : x >= 0); })) {
      p.push_back(
          fmt::format("{}{} = {}: every value must be finite and {}", prefix, key, vec(v), positive ? "> 0" : ">= 0"));
    }
  };
  table("width_ratio", width_ratio, true);
  table("height_ratio", height_ratio, true);
  table("range_sigma_rel", range_sigma_rel, false);
  if (!count.empty() && count.size() != cells)
    p.push_back(fmt::format("{}count: {} values, expected {} (or none)", prefix, count.size(), cells));
  return p;
}

std::vector<std::string> BoxRelation::Table::validate() const {
  std::vector<std::string> p;
  if (!model_id.empty() && (model_id.rfind("sha256:", 0) != 0 || model_id.size() != 7 + 16))
    p.push_back(fmt::format("box_relation.model_id = '{}': must be sha256: and 16 hex digits", model_id));
  if (!(std::isfinite(edge_noise_rel) && edge_noise_rel >= 0))
    p.push_back(fmt::format("box_relation.edge_noise_rel = {}: must be >= 0", edge_noise_rel));
  for (std::string& q : Grid::validate("box_relation.")) p.push_back(std::move(q));
  if (!window.empty())
    for (std::string& q : window.validate("box_relation.window.")) p.push_back(std::move(q));
  return p;
}

size_t BoxRelation::Grid::size_bin(double size) const { return bin_of(size_edges, size); }
size_t BoxRelation::Grid::aspect_bin(double aspect) const { return bin_of(aspect_edges, aspect); }

BoxScale BoxRelation::Grid::at(double size, double aspect) const {
  BoxScale s;
  const size_t m = aspect_edges.size() - 1;
  const size_t a = aspect_bin(aspect);
  // Linear in log(size) between the size bins' centres (geometric means), held beyond the outer ones.
  const double x = std::log(size);
  const size_t n = size_edges.size() - 1;
  const auto centre = [&](size_t i) { return 0.5 * (std::log(size_edges[i]) + std::log(size_edges[i + 1])); };
  size_t i0 = 0, i1 = 0;
  double f = 0;
  if (x <= centre(0)) {
    i0 = i1 = 0;
  } else if (x >= centre(n - 1)) {
    i0 = i1 = n - 1;
  } else {
    i0 = 0;
    while (i0 + 1 < n && centre(i0 + 1) < x) ++i0;
    i1 = i0 + 1;
    f = (x - centre(i0)) / (centre(i1) - centre(i0));
  }
  const auto lerp = [&](const std::vector<double>& v) { return (1 - f) * v[i0 * m + a] + f * v[i1 * m + a]; };
  s.width_ratio = lerp(width_ratio);
  s.height_ratio = lerp(height_ratio);
  s.range_sigma_rel = lerp(range_sigma_rel);
  return s;
}

BoxRelation BoxRelation::sphere() { return BoxRelation{}; }

BoxRelation BoxRelation::from_table(Table table, const std::string& name) {
  const std::vector<std::string> problems = table.validate();
  if (!problems.empty()) {
    std::string msg = name + ": invalid box relation:";
    for (const auto& p : problems) msg += "\n  " + p;
    throw BoxRelationError(msg);
  }
  BoxRelation r;
  r.name_ = name;
  r.model_id_ = table.model_id;
  r.table_ = std::move(table);
  return r;
}

BoxRelation BoxRelation::parse(const std::string& yaml_text, const std::string& source_name) {
  Table table;
  try {
    common::ConfigLoader loader = common::ConfigLoader::from_string(yaml_text, source_name);
    table.visit(loader);
    loader.finish({});
  } catch (const common::ConfigError& e) {
    throw BoxRelationError(e.what());
  }
  if (table.size_edges.empty() && table.aspect_edges.empty())
    throw BoxRelationError(source_name + ": box_relation.size_edges: missing (not a box relation file)");
  return from_table(std::move(table), source_name);
}

BoxRelation BoxRelation::load(const std::string& spec) {
  if (spec == "sphere") return sphere();
  if (spec.rfind("builtin:", 0) == 0) {
    if (spec != kBuiltinSmall)
      throw BoxRelationError(
          fmt::format("target.box_relation = '{}': unknown built-in (known: {}, sphere)", spec, kBuiltinSmall));
    return parse(builtin_small_box_relation(), kBuiltinSmall);
  }
  // A regular file of at most 1 MiB (a relation is a few kB): a device, FIFO or huge file is refused before reading.
  std::error_code ec;
  if (!std::filesystem::is_regular_file(spec, ec))
    throw BoxRelationError(fmt::format("{}: not a readable regular file (target.box_relation)", spec));
  if (const auto size = std::filesystem::file_size(spec, ec); ec || size > (1u << 20))
    throw BoxRelationError(fmt::format("{}: larger than 1 MiB, not a box relation file (target.box_relation)", spec));
  std::ifstream in(spec);
  if (!in) throw BoxRelationError(fmt::format("{}: cannot read the box relation file (target.box_relation)", spec));
  std::stringstream text;
  text << in.rdbuf();
  return parse(text.str(), spec);
}

std::string BoxRelation::check_model(const std::string& detections_model_id) const {
  if (is_sphere() || model_id_.empty() || detections_model_id.empty() || detections_model_id == model_id_) return "";
  return fmt::format(
      "detections_t.model_id = '{}': the box relation {} (target.box_relation) was measured for the model {}; give "
      "the relation file measured for this model (`wingman model box-relation`)",
      detections_model_id, name_, model_id_);
}

BoxScale BoxRelation::at(double box_width_px, double box_height_px, double image_width_px, int8_t pass) const {
  if (is_sphere() || !(box_width_px > 0 && box_height_px > 0 && image_width_px > 0)) return BoxScale{};
  const double aspect = box_height_px / box_width_px;
  BoxScale s = pass == kPassWindow && !table_.window.empty() ? table_.window.at(box_width_px, aspect)
                                                             : table_.at(box_width_px / image_width_px, aspect);
  s.edge_noise_rel = table_.edge_noise_rel;
  return s;
}

std::string BoxRelation::to_yaml(const std::string& header) const {
  common::ConfigPrinter printer;
  Table copy = table_;
  copy.visit(printer);
  return printer.str(header);
}

}  // namespace wingman::localizer
