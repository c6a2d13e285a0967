// SPDX-License-Identifier: MIT
// How a detector model's boxes relate to the target's bounding sphere, so that target.radius_m is the airframe's
// real bounding radius whatever drew the boxes.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace wingman::localizer {

/// A box relation file, or a box relation name, that cannot be used: the message names the file and key.
class BoxRelationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// What one box of a model stands for, relative to the box of the target's bounding sphere (same centre):
/// the sphere box is the model's box divided by the ratios. Ground-truth sphere boxes: ratios 1, spreads 0.
struct BoxScale {
  double width_ratio = 1.0;   ///< model box width / sphere box width (> 0)
  double height_ratio = 1.0;  ///< model box height / sphere box height (> 0)
  /// Relative spread of the range this leaves (1.4826 x the median absolute deviation of range / true range, over
  /// the measured boxes like this one): the view's share of the range error, which one ratio per box cannot remove.
  /// Enters the measurement covariance along the line of sight (>= 0).
  double range_sigma_rel = 0.0;
  /// Frame-to-frame wander of each box edge as a fraction of the box's width (left/right) or height (top/bottom),
  /// added to noise.edge_rel in quadrature (>= 0).
  double edge_noise_rel = 0.0;
};

/// The relation of one detector model (or of exact sphere boxes), as measured by `wingman model box-relation` on
/// renders of many airframes, views and ranges with known geometry (docs/localization.md, "Box relation"), and
/// stored in a YAML file beside the model's weights (models/wingman-small.boxes.yaml for the shipped model, also
/// built in).
///
/// The ratios are tabulated over what is known from the box alone: its size in the network's pixels (the range's
/// proxy that does not depend on the airframe's size: for the single pass its width as a fraction of the image
/// width, the image being resized to the network; for a tracker-driven window, searched at full resolution, its width
/// in image pixels) and its aspect h / w (the view: side-on, from behind, from above), in one grid per regime (the
/// same drone is a different number of network pixels in each). Between the centres of the size bins the ratios
/// are interpolated linearly in log(size), and held beyond the first and last centre; aspect bins are steps.
class BoxRelation {
 public:
  /// Exact sphere boxes (ratios 1, no spread): ground truth, or a detector trained on sphere boxes.
  static BoxRelation sphere();

  /// Reads a relation: "sphere", "builtin:wingman-small" (the shipped model's, built in), or a YAML file's path.
  /// Throws BoxRelationError naming the file and key, or the unknown built-in name.
  static BoxRelation load(const std::string& spec);

  /// Parses the YAML text of a relation file; `source_name` names it in errors. Throws BoxRelationError.
  static BoxRelation parse(const std::string& yaml_text, const std::string& source_name);

  /// detection_t::PASS_SINGLE and PASS_WINDOW (the localizer library does not need the message headers here).
  static constexpr int8_t kPassSingle = 0;
  static constexpr int8_t kPassWindow = 2;

  /// The ratios for a box of `box_width_px` x `box_height_px` in an image `image_width_px` wide, drawn by the
  /// detector pass `pass` (detection_t's PASS_ constants): a window's box (PASS_WINDOW) by the window grid when the
  /// relation has one, every other box by the main grid. Preconditions: sizes > 0 (otherwise the sphere's BoxScale is
  /// returned).
  BoxScale at(double box_width_px, double box_height_px, double image_width_px, int8_t pass = kPassSingle) const;

  /// Whether window boxes have their own grid.
  bool has_window_grid() const { return !table_.window.empty(); }

  /// The YAML text of this relation (what parse() reads back), with `header` as leading comment lines.
  std::string to_yaml(const std::string& header) const;

  /// The model the relation was measured for, as detections_t.model_id carries it ("sha256:<16 hex digits>");
  /// "" for the sphere relation (valid for any source).
  const std::string& model_id() const { return model_id_; }
  /// A readable name: "sphere", "builtin:wingman-small" or the file's path.
  const std::string& name() const { return name_; }
  bool is_sphere() const { return table_.size_edges.empty(); }

  /// "" when boxes of the model `detections_model_id` (detections_t.model_id) may use this relation: the sphere
  /// relation, a relation without a model_id, a detector that does not say (""), or the same id. Otherwise one line
  /// naming both ids and the key to set.
  std::string check_model(const std::string& detections_model_id) const;

  /// One regime's ratios: n size bins x m aspect bins, the tables row-major by size bin. What the size is depends on
  /// the regime (Table's main grid: box width / image width; its window grid: box width in image pixels).
  struct Grid {
    std::vector<double> size_edges;                                  ///< n + 1 increasing sizes > 0
    std::vector<double> aspect_edges;                                ///< m + 1 increasing h / w values > 0
    std::vector<double> width_ratio, height_ratio, range_sigma_rel;  ///< n x m each
    std::vector<int> count;  ///< boxes measured per bin (informative; 0: the bin was filled from its neighbours)

    /// Every list empty: no grid (allowed for the window grid only).
    bool empty() const {
      return size_edges.empty() && aspect_edges.empty() && width_ratio.empty() && height_ratio.empty() &&
             range_sigma_rel.empty() && count.empty();
    }
    /// One "key = value: rule" line per problem, keys `prefix` + name (e.g. "box_relation.window."); empty when
    /// consistent.
    std::vector<std::string> validate(const std::string& prefix) const;
    /// The size bin of a size and the aspect bin of an aspect (h / w), each clamped to the grid (values beyond the
    /// outer edges fall into the outer bins). Precondition: validate() is empty.
    size_t size_bin(double size) const;
    size_t aspect_bin(double aspect) const;
    /// The row-major index of that cell in the n x m tables.
    size_t cell(double size, double aspect) const {
      return size_bin(size) * (aspect_edges.size() - 1) + aspect_bin(aspect);
    }
    /// The ratios and spread at `size` > 0 and `aspect` > 0: linear in log(size) between the size bins' centres
    /// (geometric means of their edges), held beyond the outer centres; aspect bins are steps. edge_noise_rel is left
    /// 0. Precondition: validate() is empty.
    BoxScale at(double size, double aspect) const;
  };

  /// The file's content (keys `box_relation.*`, read by the one config loader), for `wingman model box-relation`
  /// and tests. The main grid (this struct's Grid part, keys `box_relation.size_edges` ...): single-pass and zoom-in
  /// boxes, sizes as box width / image width (the image is resized to the network, so this is the box's size in
  /// network pixels). The window grid (keys `box_relation.window.*`, optional): boxes of the tracker-driven windows
  /// (detection_t.pass_kind PASS_WINDOW), sizes as box width in image pixels (a window is searched at full resolution,
  /// unresized, so this is its size in network pixels); absent, window boxes use the main grid.
  struct Table : Grid {
    std::string model;            ///< the model's name (informative)
    std::string model_id;         ///< "sha256:<16 hex digits>" of the weights (detections_t.model_id)
    std::string measured_with;    ///< the command(s) that measured it (informative)
    double edge_noise_rel = 0.0;  ///< BoxScale::edge_noise_rel for every box, >= 0
    Grid window;                  ///< the windows' boxes; empty: they use the main grid

    template <class V>
    void visit(V& v) {
      v("box_relation.model", model, "the model's name");
      v("box_relation.model_id", model_id, "sha256: and the first 16 hex digits of the weights' SHA-256");
      v("box_relation.measured_with", measured_with, "the command that measured this file");
      v("box_relation.edge_noise_rel", edge_noise_rel,
        "frame-to-frame wander of each box edge, fraction of the box's width/height");
      v("box_relation.size_edges", size_edges,
        "single-pass and zoom-in boxes: box width / image width: edges of the size bins (n + 1)");
      v("box_relation.aspect_edges", aspect_edges, "box height / width: edges of the aspect bins (m + 1)");
      v("box_relation.width_ratio", width_ratio, "model box width / sphere box width, n x m row-major (median)");
      v("box_relation.height_ratio", height_ratio, "model box height / sphere box height, n x m (median)");
      v("box_relation.range_sigma_rel", range_sigma_rel,
        "relative spread of the range after the ratios, n x m (1.4826 MAD)");
      v("box_relation.count", count, "boxes measured per bin, n x m (0: filled from neighbours)");
      v("box_relation.window.size_edges", window.size_edges,
        "tracker-driven windows' boxes (full resolution): box width in image pixels: edges of the size bins (n + 1); "
        "all window keys empty: window boxes use the tables above");
      v("box_relation.window.aspect_edges", window.aspect_edges,
        "box height / width: edges of the aspect bins (m + 1)");
      v("box_relation.window.width_ratio", window.width_ratio,
        "window box width / sphere box width, n x m row-major (median)");
      v("box_relation.window.height_ratio", window.height_ratio,
        "window box height / sphere box height, n x m (median)");
      v("box_relation.window.range_sigma_rel", window.range_sigma_rel,
        "relative spread of the range after the ratios, n x m (1.4826 MAD)");
      v("box_relation.window.count", window.count, "boxes measured per bin, n x m (0: filled from neighbours)");
    }
    /// One "key = value: rule" line per problem; empty when consistent.
    std::vector<std::string> validate() const;
  };
  /// Builds a relation from a table; throws BoxRelationError (source `name`) when it is inconsistent.
  static BoxRelation from_table(Table table, const std::string& name);
  const Table& table() const { return table_; }

 private:
  std::string name_ = "sphere";
  std::string model_id_;
  Table table_;  // size_edges empty: the sphere relation
};

/// The shipped model's relation file (models/wingman-small.boxes.yaml), embedded at build time.
const char* builtin_small_box_relation();

}  // namespace wingman::localizer
