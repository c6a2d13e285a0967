// SPDX-License-Identifier: MIT
// Calibration file readers: ROS camera_info, Kalibr and OpenCV FileStorage (YAML), all with yaml-cpp.
#include "wingman/geometry/calibration.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <opencv2/core.hpp>

#include <cmath>
#include <fstream>
#include <sstream>
#include <vector>

namespace wingman::geometry {

const char* calibration_format_name(CalibrationFormat format) {
  switch (format) {
    case CalibrationFormat::kRosCameraInfo:
      return "ros_camera_info";
    case CalibrationFormat::kOpenCvFileStorage:
      return "opencv";
    case CalibrationFormat::kKalibr:
      return "kalibr";
  }
  return "?";
}

namespace {

[[noreturn]] void fail(const std::string& path, const std::string& key, const std::string& what) {
  throw CalibrationError(fmt::format("{}: key '{}': {}", path, key, what));
}

std::string read_text(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw CalibrationError(fmt::format("{}: cannot open the calibration file", path));
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

bool looks_like_opencv(const std::string& text) {
  return text.rfind("%YAML:1.0", 0) == 0 || text.rfind("%YAML 1.0", 0) == 0 ||
         text.find("!!opencv-matrix") != std::string::npos;
}

YAML::Node parse_yaml(const std::string& path, const std::string& text) {
  try {
    return YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw CalibrationError(fmt::format("{}:{}: not valid YAML: {}", path, e.mark.line + 1, e.msg));
  }
}

bool is_kalibr(const YAML::Node& root) {
  if (!root.IsMap()) return false;
  for (const auto& entry : root)
    if (entry.second.IsMap() && entry.second["intrinsics"]) return true;
  return false;
}

// --- yaml-cpp helpers: every error names the file and the dotted key ---

YAML::Node need(const std::string& path, const YAML::Node& parent, const std::string& parent_key,
                const std::string& name) {
  const std::string key = parent_key.empty() ? name : parent_key + "." + name;
  if (!parent.IsMap()) fail(path, parent_key.empty() ? "(top level)" : parent_key, "expected a mapping");
  YAML::Node node = parent[name];
  if (!node) fail(path, key, "missing");
  return node;
}

double to_double(const std::string& path, const std::string& key, const YAML::Node& node) {
  try {
    const double v = node.as<double>();
    if (!std::isfinite(v)) fail(path, key, fmt::format("expected a finite number, got '{}'", node.Scalar()));
    return v;
  } catch (const YAML::Exception&) {
    fail(path, key, "expected a number");
  }
}

int to_int(const std::string& path, const std::string& key, const YAML::Node& node) {
  try {
    return node.as<int>();
  } catch (const YAML::Exception&) {
    fail(path, key, "expected an integer");
  }
}

std::string to_string(const std::string& path, const std::string& key, const YAML::Node& node) {
  if (!node.IsScalar()) fail(path, key, "expected a string");
  return node.Scalar();
}

std::vector<double> to_doubles(const std::string& path, const std::string& key, const YAML::Node& node) {
  if (!node.IsSequence()) fail(path, key, "expected a list of numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < node.size(); ++i) out.push_back(to_double(path, fmt::format("{}[{}]", key, i), node[i]));
  return out;
}

void expect_count(const std::string& path, const std::string& key, const std::vector<double>& values, std::size_t count,
                  const std::string& what) {
  if (values.size() != count)
    fail(path, key, fmt::format("expected {} numbers ({}), got {}", count, what, values.size()));
}

/// Checks K = [fx 0 cx; 0 fy cy; 0 0 1] (row-major) and returns {fx, fy, cx, cy}.
std::vector<double> intrinsics_from_k(const std::string& path, const std::string& key, const std::vector<double>& k) {
  expect_count(path, key, k, 9, "3x3 camera matrix, row-major");
  if (k[1] != 0) fail(path, key, fmt::format("expected zero skew (element [0][1]), got {}", k[1]));
  if (k[3] != 0 || k[6] != 0 || k[7] != 0 || k[8] != 1)
    fail(path, key,
         fmt::format("expected a camera matrix [fx 0 cx; 0 fy cy; 0 0 1], got last rows [{}, {}, {}; {}, {}, {}]", k[3],
                     k[4], k[5], k[6], k[7], k[8]));
  return {k[0], k[4], k[2], k[5]};
}

CameraModel checked_camera(const std::string& path, const std::string& key, int width, int height,
                           const std::vector<double>& f, Distortion distortion, std::vector<double> coefficients,
                           std::string name) {
  try {
    return CameraModel(width, height, f[0], f[1], f[2], f[3], distortion, std::move(coefficients), std::move(name));
  } catch (const std::invalid_argument& e) {
    fail(path, key, e.what());
  }
}

Distortion ros_distortion(const std::string& path, const std::string& key, const std::string& model) {
  if (model == "plumb_bob") return Distortion::kRadTan;
  if (model == "rational_polynomial") return Distortion::kRationalPolynomial;
  if (model == "equidistant" || model == "fisheye") return Distortion::kEquidistant;
  fail(path, key, fmt::format("expected plumb_bob, rational_polynomial or equidistant, got '{}'", model));
}

CameraModel read_ros(const std::string& path, const YAML::Node& root) {
  const int width = to_int(path, "image_width", need(path, root, "", "image_width"));
  const int height = to_int(path, "image_height", need(path, root, "", "image_height"));
  const YAML::Node km = need(path, root, "", "camera_matrix");
  const std::vector<double> f = intrinsics_from_k(
      path, "camera_matrix.data", to_doubles(path, "camera_matrix.data", need(path, km, "camera_matrix", "data")));
  const std::string model = to_string(path, "distortion_model", need(path, root, "", "distortion_model"));
  const Distortion distortion = ros_distortion(path, "distortion_model", model);
  const YAML::Node dm = need(path, root, "", "distortion_coefficients");
  std::vector<double> d =
      to_doubles(path, "distortion_coefficients.data", need(path, dm, "distortion_coefficients", "data"));
  std::string name;
  if (root["camera_name"]) name = to_string(path, "camera_name", root["camera_name"]);
  if (width <= 0 || height <= 0)
    fail(path, "image_width", fmt::format("expected a size > 0, got {}x{}", width, height));
  return checked_camera(path, "distortion_coefficients.data", width, height, f, distortion, std::move(d), name);
}

CameraModel read_kalibr(const std::string& path, const YAML::Node& root, const std::string& camera) {
  const YAML::Node cam = root[camera];
  if (!cam || !cam.IsMap()) {
    std::vector<std::string> names;
    for (const auto& entry : root)
      if (entry.second.IsMap() && entry.second["intrinsics"]) names.push_back(entry.first.Scalar());
    fail(path, camera,
         fmt::format("no such camera in this Kalibr file (cameras: {}); choose one", fmt::join(names, ", ")));
  }
  const std::string model = to_string(path, camera + ".camera_model", need(path, cam, camera, "camera_model"));
  if (model != "pinhole")
    fail(path, camera + ".camera_model",
         fmt::format("expected pinhole (the only projection supported), got '{}'", model));
  std::vector<double> f = to_doubles(path, camera + ".intrinsics", need(path, cam, camera, "intrinsics"));
  expect_count(path, camera + ".intrinsics", f, 4, "fu, fv, pu, pv");
  const std::vector<double> res = to_doubles(path, camera + ".resolution", need(path, cam, camera, "resolution"));
  expect_count(path, camera + ".resolution", res, 2, "width, height");
  if (res[0] != std::floor(res[0]) || res[1] != std::floor(res[1]) || res[0] <= 0 || res[1] <= 0)
    fail(path, camera + ".resolution", fmt::format("expected two positive integers, got [{}, {}]", res[0], res[1]));
  const std::string dist_key = camera + ".distortion_model";
  const std::string dist = to_string(path, dist_key, need(path, cam, camera, "distortion_model"));
  Distortion distortion;
  if (dist == "radtan") {
    distortion = Distortion::kRadTan;
  } else if (dist == "equidistant") {
    distortion = Distortion::kEquidistant;
  } else if (dist == "none") {
    distortion = Distortion::kNone;
  } else {
    fail(path, dist_key, fmt::format("expected radtan, equidistant or none, got '{}'", dist));
  }
  std::vector<double> d;
  if (cam["distortion_coeffs"]) d = to_doubles(path, camera + ".distortion_coeffs", cam["distortion_coeffs"]);
  if (distortion == Distortion::kNone) {
    for (double c : d)
      if (c != 0) fail(path, camera + ".distortion_coeffs", "expected zeros or nothing with distortion_model none");
    d.clear();
  } else {
    expect_count(path, camera + ".distortion_coeffs", d, 4,
                 distortion == Distortion::kRadTan ? "k1, k2, r1, r2" : "k1, k2, k3, k4");
  }
  return checked_camera(path, camera + ".distortion_coeffs", static_cast<int>(res[0]), static_cast<int>(res[1]), f,
                        distortion, std::move(d), camera);
}

// --- OpenCV FileStorage (YAML) ---
// Read with yaml-cpp, not cv::FileStorage: OpenCV 4.6's YAML parser hung forever on a fuzzed file (fuzz.calibration),
// allocated rows x cols before reading data (64 GB for a fuzzed 'rows') and let std::length_error escape.

/// OpenCV writes "%YAML:1.0", which is not YAML's directive syntax; yaml-cpp reads the rest of the file as is.
std::string without_opencv_directive(const std::string& text) {
  if (text.rfind("%YAML", 0) != 0) return text;
  const std::size_t eol = text.find('\n');
  // Keep the line count (an empty line), so yaml-cpp's line numbers are the file's.
  return eol == std::string::npos ? std::string() : text.substr(eol);
}

YAML::Node first_of(const YAML::Node& root, std::initializer_list<const char*> names, std::string& found) {
  for (const char* name : names) {
    YAML::Node node = root[name];
    if (node && !node.IsNull()) {
      found = name;
      return node;
    }
  }
  found.clear();
  return YAML::Node(YAML::NodeType::Undefined);
}

/// Calibration matrices are small: an !!opencv-matrix has rows and cols in 1..64 and one channel.
constexpr int kMaxMatrixSide = 64;

std::vector<double> mat_values(const std::string& path, const std::string& key, const YAML::Node& node) {
  if (node.IsSequence()) return to_doubles(path, key, node);  // a plain list, e.g. image_size: [w, h]
  if (!node.IsMap())
    fail(path, key, "expected a matrix (!!opencv-matrix with rows, cols, dt, data) or a list of numbers");
  const YAML::Node rows_node = need(path, node, key, "rows");
  const YAML::Node cols_node = need(path, node, key, "cols");
  const YAML::Node data = need(path, node, key, "data");
  const int rows = to_int(path, key + ".rows", rows_node);
  const int cols = to_int(path, key + ".cols", cols_node);
  if (rows < 1 || rows > kMaxMatrixSide || cols < 1 || cols > kMaxMatrixSide)
    fail(path, key,
         fmt::format("expected a matrix with rows and cols in 1..{}, got {}x{}", kMaxMatrixSide, rows, cols));
  if (node["dt"]) {
    const std::string dt = to_string(path, key + ".dt", node["dt"]);
    if (dt.size() != 1 || std::string("ucwsifd").find(dt[0]) == std::string::npos)
      fail(path, key + ".dt", fmt::format("expected a one-channel element type (u, c, w, s, i, f or d), got '{}'", dt));
  }
  const std::vector<double> v = to_doubles(path, key + ".data", data);
  if (v.size() != static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols))
    fail(path, key + ".data", fmt::format("expected {}x{} = {} numbers, got {}", rows, cols, rows * cols, v.size()));
  return v;
}

int top_level_int(const std::string& path, const YAML::Node& root, const char* name) {
  return to_int(path, name, root[name]);
}

CameraModel read_opencv(const std::string& path, const std::string& text) {
  const YAML::Node root = parse_yaml(path, without_opencv_directive(text));
  if (!root.IsMap()) fail(path, "(top level)", "expected a mapping of calibration keys");
  std::string key;
  const YAML::Node k_node = first_of(root, {"camera_matrix", "cameraMatrix", "K"}, key);
  if (!k_node) fail(path, "camera_matrix", "missing (also looked for cameraMatrix, K)");
  const std::vector<double> f = intrinsics_from_k(path, key, mat_values(path, key, k_node));

  std::string d_key;
  const YAML::Node d_node = first_of(root, {"distortion_coefficients", "distCoeffs", "dist_coeffs", "D"}, d_key);
  if (!d_node) fail(path, "distortion_coefficients", "missing (also looked for distCoeffs, dist_coeffs, D)");
  std::vector<double> d = mat_values(path, d_key, d_node);

  int width = 0, height = 0;
  if (root["image_width"] || root["image_height"]) {
    if (!root["image_width"]) fail(path, "image_width", "missing (image_height is present)");
    if (!root["image_height"]) fail(path, "image_height", "missing (image_width is present)");
    width = top_level_int(path, root, "image_width");
    height = top_level_int(path, root, "image_height");
  } else {
    std::string s_key;
    const YAML::Node s_node = first_of(root, {"image_size", "imageSize"}, s_key);
    if (!s_node) fail(path, "image_width", "missing (also looked for image_height, image_size, imageSize)");
    const std::vector<double> s = mat_values(path, s_key, s_node);
    if (s.size() != 2) fail(path, s_key, fmt::format("expected [width, height], got {} numbers", s.size()));
    if (s[0] != std::floor(s[0]) || s[1] != std::floor(s[1]) || std::fabs(s[0]) > 1e6 || std::fabs(s[1]) > 1e6)
      fail(path, s_key, fmt::format("expected whole pixel counts [width, height], got [{}, {}]", s[0], s[1]));
    width = static_cast<int>(s[0]);
    height = static_cast<int>(s[1]);
  }
  if (width <= 0 || height <= 0)
    fail(path, "image_width", fmt::format("expected a size > 0, got {}x{}", width, height));

  Distortion distortion;
  if (root["distortion_model"]) {
    distortion =
        ros_distortion(path, "distortion_model", to_string(path, "distortion_model", root["distortion_model"]));
  } else if (root["fisheye_model"] && top_level_int(path, root, "fisheye_model") != 0) {
    distortion = Distortion::kEquidistant;
  } else if (d.size() == 4 || d.size() == 5) {
    distortion = Distortion::kRadTan;
  } else if (d.size() == 8) {
    distortion = Distortion::kRationalPolynomial;
  } else if (d.size() == 12 || d.size() == 14) {
    for (std::size_t i = 8; i < d.size(); ++i)
      if (d[i] != 0)
        fail(path, d_key,
             fmt::format("coefficient {} = {}: thin-prism and tilted models are not supported (expected 0)", i, d[i]));
    d.resize(8);
    distortion = Distortion::kRationalPolynomial;
  } else {
    fail(path, d_key, fmt::format("expected 4, 5, 8, 12 or 14 coefficients, got {}", d.size()));
  }
  return checked_camera(path, d_key, width, height, f, distortion, std::move(d), "");
}

}  // namespace

CalibrationFormat detect_calibration_format(const std::string& path) {
  const std::string text = read_text(path);
  if (looks_like_opencv(text)) return CalibrationFormat::kOpenCvFileStorage;
  const YAML::Node root = parse_yaml(path, text);
  if (root.IsMap() && root["camera_matrix"]) return CalibrationFormat::kRosCameraInfo;
  if (is_kalibr(root)) return CalibrationFormat::kKalibr;
  throw CalibrationError(fmt::format(
      "{}: key '(top level)': not a calibration file: expected ROS camera_info keys (image_width, camera_matrix, "
      "distortion_model, ...), an OpenCV FileStorage file (%YAML:1.0 with camera_matrix) or a Kalibr camchain "
      "(cam0: {{camera_model, intrinsics, ...}})",
      path));
}

CameraModel load_calibration(const std::string& path, const std::string& kalibr_camera) {
  const CalibrationFormat format = detect_calibration_format(path);
  const std::string text = read_text(path);
  if (format == CalibrationFormat::kOpenCvFileStorage) return read_opencv(path, text);
  const YAML::Node root = parse_yaml(path, text);
  if (format == CalibrationFormat::kRosCameraInfo) return read_ros(path, root);
  return read_kalibr(path, root, kalibr_camera);
}

CameraModel make_camera(const CameraModelOptions& o) {
  if (!o.calibration.empty()) return load_calibration(o.calibration, o.kalibr_camera);
  // Principal point at the image centre, in the calibration convention (pixel centres at integers).
  return CameraModel::pinhole(o.width, o.height, o.focal_px, o.focal_px, 0.5 * o.width - 0.5, 0.5 * o.height - 0.5);
}

}  // namespace wingman::geometry
