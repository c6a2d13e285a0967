// SPDX-License-Identifier: MIT
// Weighted box fusion: one box list from the detections of several views of the same image.
#pragma once

#include "wingman/detector/box.hpp"

#include <cstddef>
#include <vector>

namespace wingman::detector {

/// A detection of one view (pass) of an image, in the image's own pixel frame.
struct ViewBox {
  Box box;
  int view = 0;  ///< which pass found it, 0 .. view_count - 1
};

/// Weighted box fusion (Solovyev et al. 2019, "Weighted boxes fusion"), for test-time augmentation: the boxes that
/// `view_count` passes over the same image found (each already in the image's pixel frame, e.g. a mirrored pass's
/// boxes mirrored back) are grouped and each group becomes one box:
///  1. all boxes, most confident first (stable: ties keep their order in `boxes`);
///  2. each box joins the group whose fused box overlaps it most, at IoU > `iou_thresh`, among the groups that hold
///     no box of its view yet; otherwise it starts a group;
///  3. a group's box is the confidence-weighted mean of its members' centres and sizes, its confidence the sum of its
///     members' confidences over `view_count` (a box that only one of two passes found keeps half its confidence:
///     agreement between the views ranks first), its drone_score likewise from the members' drone scores, its class_id
///     the most confident member's, its pass the highest of its members' (zoom-in when any member is).
/// `boxes` is left sorted (step 1). `fused` is overwritten with the groups' boxes in the order the groups started (not
/// sorted by confidence). The groups' sums live in a thread-local array: a caller that reuses `fused` allocates
/// nothing once both have grown. Preconditions: 1 <= view_count <= 32, every box's view in 0 .. view_count - 1,
/// 0 <= iou_thresh <= 1; std::invalid_argument otherwise.
void fuse_boxes(std::vector<ViewBox>& boxes, int view_count, float iou_thresh, std::vector<Box>& fused);

/// fuse_boxes() for views that do not all see every box size (a coarse pass at a fraction of the network input
/// cannot find a small drone): `view_min_size_px[v]` is the smallest box, sqrt(w h) in image pixels, that view v
/// reports; its view_count is the vector's size. The caller drops view v's boxes below it before fusing. A group's
/// confidence is the sum of its members' over the number of views that see a box of the fused box's size (those
/// whose minimum it reaches; at least the views it holds), so that a small drone the fine views both found keeps its
/// confidence. All zeros is the fuse_boxes() above. Preconditions as above, and every minimum finite and >= 0.
void fuse_boxes(std::vector<ViewBox>& boxes, const std::vector<float>& view_min_size_px, float iou_thresh,
                std::vector<Box>& fused);

}  // namespace wingman::detector
