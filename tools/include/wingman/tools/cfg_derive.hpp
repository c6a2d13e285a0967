// SPDX-License-Identifier: MIT
// `wingman model derive-cfg`: a variant of a Darknet .cfg (fewer heads, other anchors, another input size, another
// box loss), written with the original's comments and layout kept, and checked with the detector's .cfg parser.
#pragma once

#include <string>
#include <vector>

namespace wingman::tools {

/// What to change in a .cfg. Every field left at its default leaves the .cfg as it is.
struct CfgDerivation {
  /// Keep the first `heads` [yolo] heads: everything after the heads-th [yolo] section goes, from the comment lines
  /// directly above the next section on (0: keep all).
  int heads = 0;
  /// Every [yolo]'s anchors (pixel w, h pairs), written "w,h, w,h, ..."; num becomes their count (empty: keep).
  std::vector<int> anchors;
  /// [net] width and height (0: keep).
  int width = 0;
  int height = 0;
  /// Every [yolo]'s box loss (mse, giou, diou or ciou; empty: keep) and its weight, written as given (empty: keep).
  std::string iou_loss;
  std::string iou_normalizer;
};

/// The text of `cfg_text` (named `source_name` in messages) with `d` applied. Lines not changed stay byte for byte;
/// a key a section lacks is added right after the section's header line. The result must parse
/// (detector::parse_darknet_cfg_string) and have `d.heads` heads when that is set, otherwise std::invalid_argument
/// (or the parser's DarknetFormatError) names the problem.
std::string derive_cfg_text(const std::string& cfg_text, const std::string& source_name, const CfgDerivation& d);

/// Reads `in`, derives (derive_cfg_text) and writes `out` (its folder created). Throws on a read or write failure.
void derive_cfg_file(const std::string& in, const std::string& out, const CfgDerivation& d);

}  // namespace wingman::tools
