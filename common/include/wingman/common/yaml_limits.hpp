// SPDX-License-Identifier: MIT
// Bounds on YAML input checked before it is loaded: document size and alias expansion (the "billion laughs").
#pragma once

#include <cstdint>
#include <string>

namespace wingman::common {

/// Limits of check_yaml_bounds().
struct YamlLimits {
  std::int64_t max_bytes = 1 << 20;          ///< largest document, bytes (1 MiB: configs and scenarios are KBs)
  std::int64_t max_expanded_nodes = 100000;  ///< largest node count with every alias expanded
};

/// "" when `yaml_text` is within `limits`, else one line naming `source_name` and the bound, e.g.
/// "c.yaml: YAML aliases expand to more than 100000 nodes (an alias bomb?)". Walks yaml-cpp's parse events once,
/// counting each node and, for an alias, the size of the node it names (anchors inside anchors multiply), so the
/// cost is linear in the text whatever the expansion; a syntax error is left to the loader (returns "").
std::string check_yaml_bounds(const std::string& yaml_text, const std::string& source_name,
                              const YamlLimits& limits = {});

}  // namespace wingman::common
