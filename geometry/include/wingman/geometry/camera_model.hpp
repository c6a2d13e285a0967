// SPDX-License-Identifier: MIT
// A calibrated camera: pinhole intrinsics and lens distortion (none, radtan, rational polynomial, equidistant).
#pragma once

#include "wingman/geometry/pixel_box.hpp"  // kBoxToCameraPixel, pixel_from_box()

#include <Eigen/Core>

#include <string>
#include <vector>

namespace wingman::geometry {

/// Lens distortion models. The coefficient order is OpenCV's (and ROS camera_info's):
/// - kNone: no coefficients (an ideal pinhole).
/// - kRadTan: ROS `plumb_bob`, Kalibr `radtan`: k1, k2, p1, p2[, k3] (4 or 5 coefficients; k3 = 0 if absent).
/// - kRationalPolynomial: ROS `rational_polynomial`: k1, k2, p1, p2, k3, k4, k5, k6 (8 coefficients).
/// - kEquidistant: ROS `equidistant`, Kalibr `equidistant`, OpenCV cv::fisheye: k1, k2, k3, k4 (4 coefficients),
///   theta_d = theta (1 + k1 theta^2 + k2 theta^4 + k3 theta^6 + k4 theta^8).
enum class Distortion { kNone, kRadTan, kRationalPolynomial, kEquidistant };

/// The ROS name of a distortion model: "none", "plumb_bob", "rational_polynomial", "equidistant".
const char* distortion_name(Distortion d);

/// A calibrated camera for one image size.
///
/// Frames and conventions:
/// - Camera optical frame: x right, y down, z forward (thesis Fig. 10), metres.
/// - Pixel coordinates are those of the calibration (OpenCV, ROS): the centre of the top-left pixel is (0, 0),
///   so the image spans [-0.5, width - 0.5] x [-0.5, height - 0.5]. A PixelBox (detections_t) puts (0, 0) at the
///   top-left corner of that pixel instead: u_camera = u_box - kBoxToCameraPixel (pixel_box.hpp: pixel_from_box()).
/// - "Normalized" coordinates are the undistorted image plane at z = 1: (x, y) = (X / Z, Y / Z).
///
/// The object is immutable and cheap to copy; project() and unproject() allocate nothing but unproject()'s call
/// into OpenCV.
class CameraModel {
 public:
  /// Throws std::invalid_argument naming the bad parameter: sizes > 0, focal lengths > 0 and finite, principal
  /// point finite, the number of coefficients right for the model (see Distortion), all finite.
  CameraModel(int width, int height, double fx, double fy, double cx, double cy, Distortion distortion,
              std::vector<double> coefficients, std::string name = "");

  /// An ideal pinhole camera (no distortion).
  static CameraModel pinhole(int width, int height, double fx, double fy, double cx, double cy, std::string name = "");

  int width() const { return width_; }    ///< pixels
  int height() const { return height_; }  ///< pixels
  double fx() const { return fx_; }       ///< focal length along x, pixels
  double fy() const { return fy_; }       ///< focal length along y, pixels
  double cx() const { return cx_; }       ///< principal point x, pixels (calibration convention)
  double cy() const { return cy_; }       ///< principal point y, pixels (calibration convention)
  Distortion distortion() const { return distortion_; }
  /// The distortion model's ROS name ("none" for an ideal pinhole).
  std::string model_name() const { return distortion_name(distortion_); }
  /// Distortion coefficients in the order of Distortion (kRadTan always has 5: k3 appended as 0).
  const std::vector<double>& coefficients() const { return coefficients_; }
  /// Camera name from the calibration file ("" if none).
  const std::string& name() const { return name_; }
  /// One line: "plumb_bob 1280x720 fx=... fy=... cx=... cy=... D=[...]".
  std::string describe() const;

  /// Applies the lens distortion to undistorted normalized coordinates (z = 1 plane). For kEquidistant the
  /// input must be finite (the model is defined for points in front of the camera only).
  Eigen::Vector2d distort_normalized(const Eigen::Vector2d& xy) const;

  /// Pixel coordinates of a point in the camera optical frame, distortion applied.
  /// Precondition: p_in_cam.z() > 0 (not checked; the result is meaningless otherwise).
  Eigen::Vector2d project(const Eigen::Vector3d& p_in_cam) const;

  /// Undistorted normalized coordinates (x, y) = (X / Z, Y / Z) of the ray through pixel `uv`. Uses OpenCV
  /// (cv::undistortPoints, or cv::fisheye::undistortPoints for kEquidistant) and polishes the result with a few
  /// Newton steps on distort_normalized(), so that project(unproject(uv)) == uv to ~1e-9 px wherever the
  /// distortion is invertible.
  Eigen::Vector2d undistort_to_normalized(const Eigen::Vector2d& uv) const;

  /// Unit ray in the camera optical frame through pixel `uv`, distortion removed ([x, y, 1] normalised, eq. 24).
  Eigen::Vector3d unproject(const Eigen::Vector2d& uv) const;

  /// The same camera for images resized to `width` x `height` (a uniform resize of the whole calibrated image,
  /// e.g. 1280x720 -> 640x360; the aspect may change, each axis scales on its own). With s = width / width()
  /// (and likewise for y): fx' = s fx and cx' = s (cx + 0.5) - 0.5 (pixel centres move with the resize).
  /// Distortion coefficients act on normalized coordinates and are unchanged.
  /// Not valid for a crop or a sensor mode with a different field of view (the Raspberry Pi camera's 1280x720
  /// and 1280x960 modes are different crops of the sensor and need their own calibrations).
  /// Throws std::invalid_argument if width or height is not positive.
  CameraModel scaled_to(int width, int height) const;

  /// "" if images of `width` x `height` match the calibration, else a one-line error naming both sizes.
  std::string check_image_size(int width, int height) const;

 private:
  int width_;
  int height_;
  double fx_, fy_, cx_, cy_;
  Distortion distortion_;
  std::vector<double> coefficients_;
  std::string name_;
};

}  // namespace wingman::geometry
