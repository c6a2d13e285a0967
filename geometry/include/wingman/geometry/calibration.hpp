// SPDX-License-Identifier: MIT
// Camera calibration files read as they are: ROS camera_info YAML, OpenCV FileStorage YAML, Kalibr camchain YAML.
#pragma once

#include "wingman/geometry/camera_model.hpp"
#include "wingman/geometry/camera_model_options.hpp"

#include <stdexcept>
#include <string>

namespace wingman::geometry {

/// A calibration file that cannot be read or used. what() is one line naming the file, the key and what was
/// expected, e.g. "cam.yaml: key 'camera_matrix.data': expected 9 numbers, got 6".
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The calibration file formats load_calibration() recognises.
enum class CalibrationFormat { kRosCameraInfo, kOpenCvFileStorage, kKalibr };

/// "ros_camera_info", "opencv", "kalibr".
const char* calibration_format_name(CalibrationFormat format);

/// Reads a camera calibration, detecting the format from the content:
/// - OpenCV FileStorage YAML (starts with "%YAML:1.0" or holds "!!opencv-matrix"): read with cv::FileStorage.
///   Keys: `camera_matrix` (or `cameraMatrix`, `K`), `distortion_coefficients` (or `distCoeffs`, `dist_coeffs`,
///   `D`), `image_width` + `image_height` (or `image_size` / `imageSize` as [w, h]). The distortion model is
///   `distortion_model` if present (a ROS name, or `fisheye`), else equidistant if `fisheye_model` is non-zero
///   (as OpenCV's calibration sample writes), else taken from the number of coefficients: 4 or 5 plumb_bob,
///   8 rational_polynomial; 12 or 14 only if the thin-prism and tilt terms are all zero.
/// - ROS camera_info YAML (camera_calibration_parsers; has `camera_matrix` with `data`): `image_width`,
///   `image_height`, `camera_matrix.data` (K, row-major), `distortion_model` (plumb_bob, rational_polynomial or
///   equidistant), `distortion_coefficients.data`. `rectification_matrix` and `projection_matrix` are ignored:
///   localization works on the raw (distorted) image with K and D, in the raw camera's optical frame.
/// - Kalibr camchain YAML (top-level camera entries with `intrinsics`): the entry named `kalibr_camera`
///   (e.g. "cam0"; the error lists the entries if it is absent), with `camera_model: pinhole`,
///   `intrinsics: [fu, fv, pu, pv]`, `distortion_model` (radtan, equidistant or none), `distortion_coeffs`,
///   `resolution: [width, height]`.
/// K must have zero skew. Throws CalibrationError naming the file and key (file unreadable, unknown format,
/// missing or malformed key, unsupported model).
CameraModel load_calibration(const std::string& path, const std::string& kalibr_camera = "cam0");

/// The camera of a process's camera.* keys (wingman-localizer and wingman-sim, whose defaults are the same camera):
/// the calibration file `o.calibration` read by load_calibration() (camera `o.kalibr_camera` of a Kalibr camchain),
/// or, when it is "", the ideal pinhole camera of `o.width` x `o.height` pixels with fx = fy = `o.focal_px` and the
/// principal point at the image centre in the calibration convention (pixel centres at integers: cx = width / 2 -
/// 0.5, cy = height / 2 - 0.5). width, height and focal_px are unused with a calibration file; camera_id is not part
/// of the model. Throws CalibrationError for a file that cannot be used, std::invalid_argument for a pinhole
/// CameraModel rejects.
CameraModel make_camera(const CameraModelOptions& o);

/// The format load_calibration() would read `path` as. Throws CalibrationError if it is none of them.
CalibrationFormat detect_calibration_format(const std::string& path);

}  // namespace wingman::geometry
