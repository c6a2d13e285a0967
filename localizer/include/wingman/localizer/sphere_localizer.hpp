// SPDX-License-Identifier: MIT
// Box -> 3D: the target is a sphere of known radius; its position in the camera frame from a detection box.
#pragma once

#include <wingman/geometry/camera_model.hpp>
#include "wingman/localizer/box_relation.hpp"
#include "wingman/localizer/measurement.hpp"

#include <string>
#include <vector>

namespace wingman::localizer {

/// How the distance to the target is computed.
enum class RangeMethod {
  /// Default. Each box edge back-projects to a plane through the camera centre tangent to the sphere; the
  /// centre c solves n_i . c = r for the uncut edges (least squares). Exact for any position in the field of view;
  /// with distortion the planes are taken at the tangency points, iterated to convergence.
  kExact,
  /// The thesis: direction of the box centre (eq. 24) times the distance of eq. 32 from the rays through the
  /// left and right edge midpoints (top and bottom if the width is cut). Exact only on the optical axis.
  kThesis,
  /// As kThesis with the simplified eq. 33 (l = r / tan(alpha)); for comparison only.
  kThesisEq33,
};

/// Options of the sphere localizer: the target's size, the range method and limits, the pixel noise model and
/// the border rule. Keys as in the localizer's YAML.
struct SphereLocalizerOptions {
  /// Bounding-sphere radius of the target airframe, metres: the farthest point of the drone from its centre, the
  /// propeller tips swept round included (r_spin). A physical fact of the airframe, the same for every detector: the
  /// box relation below says how a model's boxes relate to this sphere. Default: DJI F450, 0.348 m
  /// (shared/meshes/README.md; the thesis used 0.29 m). Holybro X500 V2: 0.429, Tarot T650: 0.494, 3DR Iris: 0.390.
  double radius_m = 0.348;
  /// How the CNN's boxes relate to the bounding sphere's box (box_relation.hpp): builtin:wingman-small (the shipped
  /// model's, measured: models/wingman-small.boxes.yaml), the relation file beside another model's weights, or
  /// sphere (boxes are the sphere's: ratio 1). Ground-truth detections (detections_t.SOURCE_GROUND_TRUTH) always use
  /// sphere. A CNN detections_t whose model_id is not the relation's is dropped, naming both.
  std::string box_relation = "builtin:wingman-small";
  /// "exact" (tangent planes, default), "thesis" (eq. 24 + eq. 32) or "thesis_eq33" (eq. 24 + eq. 33).
  std::string range_method = "exact";
  /// Distances below this are rejected, metres. Must exceed radius_m.
  double min_range_m = 0.5;
  /// Distances above this are rejected, metres.
  double max_range_m = 100.0;
  /// Standard deviation of each box edge, independently, pixels (> 0).
  double edge_noise_px = 1.0;
  /// Plus this fraction of the box's width (left and right edges) or height (top and bottom), added to edge_noise_px
  /// in quadrature (>= 0). A CNN's box edges wander with the box's size (the shipped model: about 10-20 % of the
  /// width frame to frame, which its box relation's edge_noise_rel adds for its boxes; box_relation.hpp); a covariance
  /// that ignores it makes the tracker's gate reject the leader's own detections and split it into many tracks
  /// (docs/localization.md).
  double edge_noise_rel = 0.0;
  /// Standard deviation of the box centre (a shift of the whole box, common to its edges), pixels (>= 0).
  double centre_noise_px = 0.5;
  /// A box edge within this many pixels of the image edge is cut by the border, pixels (>= 0). 4: a CNN draws the
  /// box of a drone the border cuts a few pixels inside the image (the shipped model's edge lay 3 px in where the
  /// true box was cut at 0.5 px, at 1280x720: two of its network pixels), and read as a whole edge that box puts the
  /// drone twice as far (docs/localization.md, "Border rule").
  double border_margin_px = 4.0;

  template <class V>
  void visit(V& v) {
    v("target.radius_m", radius_m,
      "bounding-sphere radius of the target airframe, propeller tips included, metres (DJI F450: 0.348)");
    v("target.box_relation", box_relation,
      "how the CNN's boxes relate to that sphere: builtin:wingman-small, a relation file, or sphere (ratio 1)");
    v("range.method", range_method, "exact (tangent planes), thesis (eq. 24 + 32) or thesis_eq33 (eq. 33)");
    v("range.min_m", min_range_m, "reject distances below this, metres (> target.radius_m)");
    v("range.max_m", max_range_m, "reject distances above this, metres");
    v("noise.edge_px", edge_noise_px, "standard deviation of each box edge, pixels");
    v("noise.edge_rel", edge_noise_rel,
      "plus this fraction of the box width (left/right edges) or height (top/bottom), in quadrature (CNN boxes)");
    v("noise.centre_px", centre_noise_px, "standard deviation of the box centre (common shift), pixels");
    v("border.margin_px", border_margin_px, "an edge this close to the image edge is cut by the border, pixels");
  }
  /// Problems as "key = value: rule", empty if valid.
  std::vector<std::string> validate() const;
  /// range_method parsed. Precondition: validate() is empty.
  RangeMethod method() const;
};

/// The outcome of localize_box().
struct LocalizeResult {
  bool ok = false;     ///< false: rejected (see reason); measurement is not meaningful
  std::string reason;  ///< one line, naming the field, when !ok
  /// When ok and measurement.range_valid: position, range, bearing and covariance. When ok and !range_valid
  /// (box cut by the border so no size is usable): bearing_in_cam only; range = 0, p_target_in_cam = 0 and
  /// cov_p_in_cam = 0.
  CameraMeasurement measurement;
  int edges_used = 0;  ///< uncut box edges the range was computed from (exact: 2..4; thesis: 2)
  int iterations = 0;  ///< tangency iterations of the exact method (1 without distortion)
};

/// Localizes the sphere-modelled target seen as `box` (PixelBox coordinates: origin at the top-left pixel's
/// corner) through `camera`, in the camera optical frame (x right, y down, z forward).
///
/// Border rule: an edge is cut when it lies within options.border_margin_px of the image edge (left <= m,
/// right >= width - m, top <= m, bottom >= height - m). Exact method: cut edges are dropped from the least
/// squares; with 3 or 4 uncut edges the centre is solved; with only the two edges of one dimension whole, the
/// centre is the point of their planes' intersection line closest to the ray through the box centre; otherwise
/// range_valid = false with the bearing of the box centre. Thesis methods: the width gives the range; if the width
/// is cut the height does; if both are cut range_valid = false.
///
/// Covariance: see docs/localization.md and sphere_localizer.cpp. cov_p_in_cam = J S J^T with J = dp/d(edges)
/// and S = edge_px^2 I + centre_px^2 (1 on each axis's 2x2 block).
///
/// Box relation: `scale` says what the box stands for (BoxRelation::at() for the box; the default: the bounding
/// sphere's own box). The left/right edge planes lie width_ratio x radius_m from the centre and the top/bottom ones
/// height_ratio x radius_m; scale.edge_noise_rel adds to noise.edge_rel in quadrature, and scale.range_sigma_rel adds
/// range_sigma_rel^2 p p^T to the covariance.
///
/// Rejected (ok = false): a non-finite box field, w or h <= 0, a centre outside the image, no sphere fitting the
/// edges, a distance outside [min_range_m, max_range_m]. Precondition: options.validate() is empty.
LocalizeResult localize_box(const geometry::PixelBox& box, const geometry::CameraModel& camera,
                            const SphereLocalizerOptions& options, const BoxScale& scale = {});

}  // namespace wingman::localizer
