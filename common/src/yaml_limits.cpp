// SPDX-License-Identifier: MIT
// YAML size and alias-expansion bounds, from yaml-cpp's parse events.
#include "wingman/common/yaml_limits.hpp"

#include <fmt/format.h>
#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/exceptions.h>
#include <yaml-cpp/parser.h>

#include <limits>
#include <map>
#include <sstream>
#include <vector>

namespace wingman::common {
namespace {

/// Counts nodes with aliases expanded; stops counting (saturates) past the limit.
class ExpansionCounter : public YAML::EventHandler {
 public:
  explicit ExpansionCounter(std::int64_t limit) : limit_(limit) {}
  bool over() const { return nodes_ > limit_; }

  void OnDocumentStart(const YAML::Mark&) override {}
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t anchor) override { leaf(anchor); }
  void OnAlias(const YAML::Mark&, YAML::anchor_t anchor) override {
    const auto it = sizes_.find(anchor);
    add(it == sizes_.end() ? 1 : it->second);
  }
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t anchor, const std::string&) override {
    leaf(anchor);
  }
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t anchor,
                       YAML::EmitterStyle::value) override {
    open(anchor);
  }
  void OnSequenceEnd() override { close(); }
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t anchor, YAML::EmitterStyle::value) override {
    open(anchor);
  }
  void OnMapEnd() override { close(); }

 private:
  void add(std::int64_t n) {
    nodes_ =
        n > std::numeric_limits<std::int64_t>::max() - nodes_ ? std::numeric_limits<std::int64_t>::max() : nodes_ + n;
  }
  void leaf(YAML::anchor_t anchor) {
    add(1);
    if (anchor != YAML::NullAnchor) sizes_[anchor] = 1;
  }
  void open(YAML::anchor_t anchor) {
    add(1);
    open_.push_back({anchor, nodes_});
  }
  void close() {
    if (open_.empty()) return;
    const auto [anchor, start] = open_.back();
    open_.pop_back();
    if (anchor != YAML::NullAnchor) sizes_[anchor] = nodes_ - start + 1;
  }

  std::int64_t limit_;
  std::int64_t nodes_ = 0;
  std::map<YAML::anchor_t, std::int64_t> sizes_;  ///< nodes of each anchored node, aliases inside expanded
  std::vector<std::pair<YAML::anchor_t, std::int64_t>> open_;
};

}  // namespace

std::string check_yaml_bounds(const std::string& yaml_text, const std::string& source_name, const YamlLimits& limits) {
  if (static_cast<std::int64_t>(yaml_text.size()) > limits.max_bytes)
    return fmt::format("{}: {} bytes: larger than the {} bytes a YAML file may have", source_name, yaml_text.size(),
                       limits.max_bytes);
  std::istringstream in(yaml_text);
  ExpansionCounter counter(limits.max_expanded_nodes);
  try {
    YAML::Parser parser(in);
    while (parser.HandleNextDocument(counter)) {
      if (counter.over()) break;
    }
  } catch (const YAML::Exception&) {
    return "";  // the loader reports syntax errors with their line
  }
  if (counter.over())
    return fmt::format("{}: YAML aliases expand to more than {} nodes (an alias bomb?)", source_name,
                       limits.max_expanded_nodes);
  return "";
}

}  // namespace wingman::common
