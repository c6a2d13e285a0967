// SPDX-License-Identifier: MIT
// A detection box (centre, size, confidence) and its intersection over union.
#pragma once

#include <cstdint>
#include <vector>

namespace wingman::detector {

/// Which pass of the detector drew a box; the values are detection_t's PASS_ constants.
enum class Pass : int8_t {
  kSingle = 0,  ///< the whole image resized to the network
  kZoomIn = 1,  ///< a zoom-in crop around a single-pass box, resized to the network (Algorithm 2)
  kWindow = 2,  ///< a full-resolution window where a track or the motion cue predicted a drone (no resize)
};

/// One detection. Coordinates are pixels of the image the box refers to (network input, crop or full
/// image, as each function says); the origin is the top-left corner of the top-left pixel.
struct Box {
  float cx = 0.0f;            ///< centre x, pixels
  float cy = 0.0f;            ///< centre y, pixels
  float w = 0.0f;             ///< width, pixels (>= 0)
  float h = 0.0f;             ///< height, pixels (>= 0)
  float confidence = 0.0f;    ///< objectness x the probability of the box's class (class_id), 0..1
  Pass pass = Pass::kSingle;  ///< which pass drew the box (its sizes relate to the drone differently per pass)
  /// the most probable class of the model's [yolo]/[region] head: 0 = drone; a multi-class model's others are
  /// distractors (models/wingman-small.md names them: 1 airplane, 2 bird, 3 helicopter)
  int class_id = 0;
  /// objectness x the probability of class 0 (drone), 0..1: what a drone follower ranks by; equals `confidence` when
  /// class_id is 0 and for a single-class model
  float drone_score = 0.0f;
};

/// Intersection over union of two boxes in the same pixel frame, 0..1 (0 when both are empty).
float iou(const Box& a, const Box& b);

/// The part of `b` inside the image [0, width] x [0, height] (pixels; width, height >= 0), as labels are: a box
/// that reaches past the frame (a drone cut off by the border) keeps its visible part. Confidence and flags are
/// kept; a box wholly outside the image comes back with w = 0 or h = 0.
Box clip_to_image(const Box& b, float width, float height);

/// clip_to_image() of each box, in order, leaving out those wholly outside the image.
std::vector<Box> clip_to_image(const std::vector<Box>& boxes, float width, float height);

/// The box mirrored about the vertical centre line of an image `width` pixels wide (a horizontal flip: x -> width - x,
/// the origin at the top-left corner of the top-left pixel). Size, confidence and flags are kept.
Box mirror_horizontally(const Box& b, float width);

}  // namespace wingman::detector
