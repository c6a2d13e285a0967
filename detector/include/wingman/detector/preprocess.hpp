// SPDX-License-Identifier: MIT
// From camera frames to network input: pixel-format conversion, Algorithm 2's regions, resize, CHW floats.
#pragma once

#include "wingman/detector/box.hpp"

#include <wingman/image_t.hpp>

#include <opencv2/core.hpp>

#include <string>

namespace wingman::detector {

/// Converts an image_t (GRAY8, BGR8, YUYV, MJPEG) to an 8-bit 3-channel BGR image (a new buffer).
/// Returns an empty Mat and sets `*error` (if not null) to one line naming the field, its value and the
/// rule when the message is impossible: width or height < 1, stride below width x bytes per pixel (or
/// not 0 for MJPEG), odd width for YUYV, size below height x stride, unknown pixel_format, or a JPEG that
/// does not decode to width x height.
cv::Mat image_to_bgr(const wingman::image_t& image, std::string* error);

/// Algorithm 2's detection region in full-image pixels: with `subsquare`, the centred
/// min(width, height) square (the centred h x h square of a wider image); else the whole image.
/// The square's left edge is (width - side) / 2 rounded down.
cv::Rect detection_region(cv::Size image, bool subsquare);

/// Algorithm 2's zoom-in crop: a net-sized rectangle of the full-resolution image centred on
/// (cx, cy) (full-image pixels), shifted to lie inside the image. Where the image is smaller than the
/// network input in a dimension the crop spans the image in that dimension (and is stretched later).
cv::Rect zoom_crop(cv::Size image, cv::Size net, float cx, float cy);

/// Maps a box from network-input pixels (net.width x net.height) to full-image pixels, given the image
/// region `roi` that was resized (stretched) to the network input: x_full = roi.x + x_net * roi.width / net.width,
/// likewise for y; sizes scale by roi.width / net.width and roi.height / net.height.
Box network_to_image(const Box& box_in_net, const cv::Rect& roi, cv::Size net);

/// Resizes `bgr(roi)` to `net` (bilinear, stretched: cv::INTER_LINEAR) and writes it to `chw` as
/// 3 x net.height x net.width float32 RGB planes scaled to [0, 1] (the network input).
/// `resized` is scratch space reused between calls (no allocation once it has the network size).
/// Preconditions: bgr is CV_8UC3; roi lies inside it; chw has room for 3 * net.area() floats.
void to_network_input(const cv::Mat& bgr, const cv::Rect& roi, cv::Size net, cv::Mat& resized, float* chw);

}  // namespace wingman::detector
