// SPDX-License-Identifier: MIT
// Reading a camera rig file (camera_rig.hpp), with the mounts of a Kalibr camchain.
#include "wingman/geometry/camera_rig.hpp"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>
#include <wingman/common/config.hpp>
#include <wingman/common/yaml_limits.hpp>
#include <wingman/common/yaml_mapping_reader.hpp>

#include <Eigen/Geometry>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

namespace wingman::geometry {
namespace fs = std::filesystem;

const RigCamera* CameraRig::find(int camera_id) const {
  for (const RigCamera& c : cameras)
    if (c.camera.camera_id == camera_id) return &c;
  return nullptr;
}

namespace {

/// Reads and parses the YAML file `path` into `root` within common::check_yaml_bounds. Returns "" or the one-line
/// problem ("<path>: cannot read the <what>", the bound it breaks, "<path>:<line>: not valid YAML: ...").
std::string read_yaml_file(const std::string& path, const char* what, YAML::Node& root) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return fmt::format("{}: cannot read the {}", path, what);
  std::ostringstream text;
  text << in.rdbuf();
  if (std::string bad = common::check_yaml_bounds(text.str(), path); !bad.empty()) return bad;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    return fmt::format("{}:{}: not valid YAML: {}", path, e.mark.line + 1, e.msg);
  }
  return "";
}

/// The 3x3 matrix of 9 row-major values. Precondition: R_row_major.size() == 9.
Eigen::Matrix3d from_row_major(const std::vector<double>& R_row_major) {
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R_row_major.data());
}

/// Row-major values of a 3x3 matrix.
std::vector<double> row_major(const Eigen::Matrix3d& R) {
  std::vector<double> out(9);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) out[static_cast<size_t>(3 * r + c)] = R(r, c);
  return out;
}

/// R_cam_to_body of the default forward camera turned left by `yaw_deg` about body z, then tilted up by
/// `pitch_deg`, row-major.
std::vector<double> mount_rotation(double yaw_deg, double pitch_deg) {
  const Eigen::Matrix3d R_forward = from_row_major(ExtrinsicsOptions().R_cam_to_body);
  const double deg = M_PI / 180.0;
  // Tilting up turns the optical axis (body +x) towards body +z: a rotation about body y by -pitch.
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(yaw_deg * deg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(-pitch_deg * deg, Eigen::Vector3d::UnitY()))
                                .toRotationMatrix() *
                            R_forward;
  return row_major(R);
}

/// A visit() target that reads `prefix` + key through `reader` (the chain's first camera: camchain.extrinsics.*).
struct PrefixedReader {
  common::YamlMappingReader& reader;
  std::string prefix;
  template <class T>
  void operator()(const std::string& key, T& value, const char* doc) {
    reader(prefix + key, value, doc);
  }
};

/// Reads one camera's mount, `at`mount.yaw_deg / pitch_deg or `at`extrinsics.* (`at`: "" for a rig camera,
/// "camchain." for the chain's first camera), into `extrinsics` and checks it. Returns the first of these keys given
/// ("" when none: the defaults).
std::string read_mount(common::YamlMappingReader& r, const std::string& at, ExtrinsicsOptions& extrinsics) {
  const std::string keys[] = {at + "mount.yaw_deg", at + "mount.pitch_deg", at + "extrinsics.R_cam_to_body",
                              at + "extrinsics.p_cam_in_body"};
  std::string first_given;
  for (const std::string& key : keys)
    if (first_given.empty() && r.has(key)) first_given = key;
  const bool has_R = r.has(keys[2]);
  PrefixedReader prefixed{r, at};
  extrinsics.visit(prefixed);
  double yaw_deg = 0.0, pitch_deg = 0.0;
  const bool has_mount = r.has(keys[0]) || r.has(keys[1]);
  r(keys[0], yaw_deg, "turned left about body z from the forward camera, degrees");
  r(keys[1], pitch_deg, "tilted up, degrees");
  if (has_mount && has_R)
    r.problem(
        keys[0],
        fmt::format("give the mount either as {}mount.yaw_deg/pitch_deg or as {}extrinsics.R_cam_to_body", at, at));
  if (!std::isfinite(yaw_deg) || !std::isfinite(pitch_deg))
    r.problem(keys[0], "mount.yaw_deg and mount.pitch_deg must be finite");
  else if (has_mount)
    extrinsics.R_cam_to_body = mount_rotation(yaw_deg, pitch_deg);
  for (const std::string& line : extrinsics.validate()) r.validation_problem(at + line);
  return first_given;
}

/// The rigid transform of a checked rotation and translation (the rotation projected onto the nearest rotation, so
/// that products of several stay orthonormal to rounding).
Eigen::Isometry3d rigid(const Eigen::Matrix3d& R, const Eigen::Vector3d& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = p;
  return T;
}

/// The keys Kalibr writes in a camchain entry (kalibr_calibrate_cameras, kalibr_calibrate_imu_camera; the wiki's
/// "Yaml formats"). The rig reads T_cam_imu and T_cn_cnm1; the intrinsics are make_camera()'s; the rest is ignored.
constexpr const char* kKalibrEntryKeys[] = {"camera_model", "intrinsics",       "distortion_model", "distortion_coeffs",
                                            "resolution",   "rostopic",         "cam_overlaps",     "T_cn_cnm1",
                                            "T_cam_imu",    "timeshift_cam_imu"};

/// A Kalibr camchain file as the rig reads it: its entries in file order and the transforms the rig's cameras use,
/// every problem recorded once as "<file>:<line>: <entry>.<key>: ...".
class KalibrChain {
 public:
  /// Reads `path` (a problem for an unreadable file, bad YAML or a top level that is not a mapping of entries).
  KalibrChain(std::string path, std::vector<std::string>* problems) : path_(std::move(path)), problems_(problems) {
    YAML::Node root;
    if (std::string bad = read_yaml_file(path_, "Kalibr camchain file", root); !bad.empty()) {
      problems_->push_back(bad);
      return;
    }
    if (!root.IsMap()) {
      problems_->push_back(
          fmt::format("{}: (top level): expected a Kalibr camchain, a mapping of cameras (cam0: {{...}}, "
                      "cam1: {{...}}, ...), got {}",
                      path_, common::YamlMappingReader::describe(root)));
      return;
    }
    for (const auto& item : root) entries_.push_back(Entry{item.first.Scalar(), item.first, item.second, {}, {}});
    loaded_ = true;
  }

  bool loaded() const { return loaded_; }
  const std::string& path() const { return path_; }

  /// The index of the entry `name` in file order, or -1.
  int find(const std::string& name) const {
    for (size_t i = 0; i < entries_.size(); ++i)
      if (entries_[i].name == name) return static_cast<int>(i);
    return -1;
  }
  const std::string& name(size_t index) const { return entries_[index].name; }
  /// The entries' names, "cam0, cam1, ...", for messages.
  std::string names() const {
    std::string out;
    for (const Entry& e : entries_) out += (out.empty() ? "" : ", ") + e.name;
    return out.empty() ? "none" : out;
  }

  /// Checks that an entry named cam<n> is the n-th (from 0): a camera-only chain runs in file order, which in
  /// Kalibr's files is cam0, cam1, ...; a file listing them otherwise (cam10 sorted before cam2) is refused.
  void check_kalibr_order() {
    for (size_t i = 0; i < entries_.size(); ++i) {
      const std::string& n = entries_[i].name;
      if (n.size() < 4 || n.compare(0, 3, "cam") != 0 || n.find_first_not_of("0123456789", 3) != std::string::npos)
        continue;
      if (n != fmt::format("cam{}", i))
        entry_problem(i, "",
                      fmt::format("is entry {} of the file (from 0): a camera chain runs in file order, each "
                                  "T_cn_cnm1 from the entry before, so cam<n> must be entry n",
                                  i));
    }
  }

  /// The rigid transform `key` (T_cam_imu or T_cn_cnm1) of entry `index`; nullopt when it is absent (the problem
  /// says `when_absent`) or is not a 4x4 rigid transform. Each entry's key is checked and reported once.
  std::optional<Eigen::Isometry3d> transform(size_t index, const std::string& key, const std::string& when_absent) {
    Entry& e = entries_[index];
    if (const auto it = e.transforms.find(key); it != e.transforms.end()) return it->second;
    std::optional<Eigen::Isometry3d>& out = e.transforms[key];
    common::YamlMappingReader* r = reader(index);
    if (r == nullptr) return out;
    const YAML::Node node = r->take(key);
    if (!node.IsDefined()) {
      entry_problem(index, key, "missing: " + when_absent);
      return out;
    }
    out = parse_transform(*r, key, node);
    return out;
  }

  /// Records the keys that Kalibr does not write, in every entry read.
  void finish() {
    for (Entry& e : entries_)
      if (e.reader) e.reader->finish(fmt::format(" (Kalibr's camchain keys: {})", fmt::join(kKalibrEntryKeys, ", ")));
  }

 private:
  struct Entry {
    std::string name;
    YAML::Node key;    // the entry's name in the file, for its line
    YAML::Node value;  // its mapping
    std::optional<common::YamlMappingReader> reader;
    std::map<std::string, std::optional<Eigen::Isometry3d>> transforms;  // key -> checked transform (or none)
  };

  /// The reader of entry `index` (made on first use, every Kalibr key marked known), or nullptr when the entry is
  /// not a mapping (then reported).
  common::YamlMappingReader* reader(size_t index) {
    Entry& e = entries_[index];
    if (!e.value.IsMap()) {
      if (!e.reader) {
        e.reader.emplace(path_, YAML::Node(), e.name + ".", problems_);  // marks it as reported
        entry_problem(index, "",
                      "expected a camera's mapping (camera_model, intrinsics, ...), got " +
                          common::YamlMappingReader::describe(e.value));
      }
      return nullptr;
    }
    if (!e.reader) {
      e.reader.emplace(path_, e.value, e.name + ".", problems_);
      for (const char* key : kKalibrEntryKeys) (void)e.reader->take(key);
    }
    return &*e.reader;
  }

  /// "<file>:<line of the entry>: <entry>[.<key>]: <message>".
  void entry_problem(size_t index, const std::string& key, const std::string& message) {
    const Entry& e = entries_[index];
    problems_->push_back(
        fmt::format("{}:{}: {}{}{}: {}", path_, e.key.Mark().line + 1, e.name, key.empty() ? "" : ".", key, message));
  }

  /// A 4x4 list of 4 lists of finite numbers, last row [0, 0, 0, 1], rotation block orthonormal with determinant +1.
  static std::optional<Eigen::Isometry3d> parse_transform(common::YamlMappingReader& r, const std::string& key,
                                                          const YAML::Node& node) {
    const char* shape = "expected a 4x4 transform: a list of 4 rows, each a list of 4 numbers";
    if (!node.IsSequence() || node.size() != 4) {
      r.problem(key, fmt::format("{}, got {}", shape,
                                 node.IsSequence() ? fmt::format("{} rows", node.size())
                                                   : common::YamlMappingReader::describe(node)));
      return std::nullopt;
    }
    Eigen::Matrix4d T;
    for (size_t row = 0; row < 4; ++row) {
      const YAML::Node values = node[row];
      if (!values.IsSequence() || values.size() != 4) {
        r.problem(key, fmt::format("{}, got row {} with {}", shape, row,
                                   values.IsSequence() ? fmt::format("{} values", values.size())
                                                       : common::YamlMappingReader::describe(values)));
        return std::nullopt;
      }
      for (size_t col = 0; col < 4; ++col) {
        double v = 0.0;
        if (!values[col].IsScalar() || !YAML::convert<double>::decode(values[col], v) || !std::isfinite(v)) {
          r.problem(key, fmt::format("row {}, column {}: expected a finite number, got {}", row, col,
                                     common::YamlMappingReader::describe(values[col])));
          return std::nullopt;
        }
        T(static_cast<int>(row), static_cast<int>(col)) = v;
      }
    }
    if (T.row(3) != Eigen::RowVector4d(0, 0, 0, 1)) {
      r.problem(key, fmt::format("the last row must be [0, 0, 0, 1] (a rigid transform), got [{}, {}, {}, {}]", T(3, 0),
                                 T(3, 1), T(3, 2), T(3, 3)));
      return std::nullopt;
    }
    const Eigen::Matrix3d R = T.topLeftCorner<3, 3>();
    if (const auto bad = rotation_problems(key + " (its rotation block)", row_major(R)); !bad.empty()) {
      r.validation_problem(bad.front());
      return std::nullopt;
    }
    return rigid(R, T.topRightCorner<3, 1>());
  }

  std::string path_;
  std::vector<std::string>* problems_;
  bool loaded_ = false;
  std::vector<Entry> entries_;
};

/// Where a camchain's frame sits on the body: the IMU (T_cam_imu in every entry) or its first entry (T_cn_cnm1).
struct ChainBase {
  bool from_imu = true;                                              ///< T_cam_imu; else T_cn_cnm1 from the first entry
  Eigen::Isometry3d T_base_to_body = Eigen::Isometry3d::Identity();  ///< IMU or first camera -> body (FLU)
};

/// The camera -> body transform of chain entry `index` for the rig camera `who` ("cameras[2]"), or nullopt (the
/// chain's problems recorded).
std::optional<Eigen::Isometry3d> chain_camera_to_body(KalibrChain& chain, const ChainBase& base, size_t index,
                                                      const std::string& who) {
  if (base.from_imu) {
    const auto T_cam_imu = chain.transform(
        index, "T_cam_imu",
        fmt::format("{} takes its mount from the IMU's (camchain.R_imu_to_body, p_imu_in_body); a camera-only "
                    "camchain (kalibr_calibrate_cameras, T_cn_cnm1) needs its first camera's mount instead: "
                    "camchain.mount.* or camchain.extrinsics.*",
                    who));
    if (!T_cam_imu) return std::nullopt;
    return base.T_base_to_body * T_cam_imu->inverse();
  }
  Eigen::Isometry3d T_cam_to_body = base.T_base_to_body;  // entry 0's
  bool complete = true;
  for (size_t n = 1; n <= index; ++n) {
    const auto T_cn_cnm1 = chain.transform(
        n, "T_cn_cnm1",
        fmt::format("{} ({}) takes its mount along the chain from {} (camchain.mount/extrinsics), each entry's "
                    "T_cn_cnm1 from the entry before it",
                    who, chain.name(index), chain.name(0)));
    if (!T_cn_cnm1)
      complete = false;
    else
      T_cam_to_body = T_cam_to_body * T_cn_cnm1->inverse();
  }
  if (!complete) return std::nullopt;
  return T_cam_to_body;
}

/// Whether two paths name the same file (equivalent when both exist, else the same normalised path).
bool same_file(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  if (fs::exists(a, ec) && fs::exists(b, ec)) return fs::equivalent(a, b, ec);
  return a.lexically_normal() == b.lexically_normal();
}

/// The camchain.* keys: the chain file and where its frame sits on the body. Returns the checked base (problems
/// recorded through `top`); `file` is "" when the rig has no camchain.
ChainBase read_chain_base(common::YamlMappingReader& top, const fs::path& folder, std::string& file) {
  ChainBase base;
  top("camchain.file", file, "Kalibr camchain file, relative to the rig file's folder");
  std::vector<double> R_imu_to_body = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  std::vector<double> p_imu_in_body = {0, 0, 0};
  const bool has_imu = top.has("camchain.R_imu_to_body") || top.has("camchain.p_imu_in_body");
  top("camchain.R_imu_to_body", R_imu_to_body, "rotation IMU frame -> body (FLU), 3x3 row-major");
  top("camchain.p_imu_in_body", p_imu_in_body, "IMU origin in the body (FLU) [x, y, z], m");
  ExtrinsicsOptions first_camera;
  const std::string first_camera_key = read_mount(top, "camchain.", first_camera);
  if (top.has("camchain")) {  // camchain: FILE, or camchain: with nothing
    (void)top.take("camchain");
    top.problem("camchain", "expected a mapping: camchain: {file: CAMCHAIN.yaml, ...}");
  }
  if (file.empty()) {
    if (has_imu || !first_camera_key.empty())
      top.problem("camchain.file", "missing: the Kalibr camchain file these camchain keys are for");
    return base;
  }
  if (fs::path(file).is_relative()) file = (folder / file).string();
  if (!fs::is_regular_file(file))
    top.problem("camchain.file",
                fmt::format("'{}' is not a file (a relative path is taken from the rig file's folder)", file));
  if (!first_camera_key.empty()) {
    if (has_imu)
      top.problem(first_camera_key,
                  "give the chain's place on the body either as the IMU's (camchain.R_imu_to_body, p_imu_in_body: a "
                  "camchain-imucam's T_cam_imu) or as its first camera's (camchain.mount.*, extrinsics.*: T_cn_cnm1), "
                  "not both");
    const Extrinsics e = Extrinsics::from_options(first_camera.validate().empty() ? first_camera : ExtrinsicsOptions{});
    base.from_imu = false;
    base.T_base_to_body = rigid(e.R_cam_to_body, e.p_cam_in_body);
    return base;
  }
  for (const std::string& line : rotation_problems("camchain.R_imu_to_body", R_imu_to_body))
    top.validation_problem(line);
  bool p_ok = p_imu_in_body.size() == 3;
  for (double v : p_imu_in_body) p_ok = p_ok && std::isfinite(v);
  if (!p_ok)
    top.validation_problem(common::problem("camchain.p_imu_in_body",
                                           fmt::format("[{}]", fmt::join(p_imu_in_body, ", ")),
                                           "must be 3 finite numbers [x, y, z] in metres"));
  else if (rotation_problems("camchain.R_imu_to_body", R_imu_to_body).empty())
    base.T_base_to_body =
        rigid(from_row_major(R_imu_to_body), Eigen::Vector3d(p_imu_in_body[0], p_imu_in_body[1], p_imu_in_body[2]));
  return base;
}

}  // namespace

CameraRig load_camera_rig(const std::string& path) {
  YAML::Node root;
  if (const std::string bad = read_yaml_file(path, "camera rig file", root); !bad.empty())
    throw common::ConfigError(bad);

  CameraRig rig;
  rig.source = path;
  std::vector<std::string> problems;
  const fs::path folder = fs::path(path).parent_path();
  common::YamlMappingReader top(path, root, "", &problems);
  const std::vector<YAML::Node> items = top.take_list("cameras", true);
  const ChainBase chain_base = read_chain_base(top, folder, rig.camchain);
  top.finish(" (a rig file has the keys cameras and camchain)");
  if (items.empty() && problems.empty()) problems.push_back(fmt::format("{}: cameras: the list is empty", path));
  if (static_cast<int>(items.size()) > CameraRig::kMaxCameras)
    problems.push_back(fmt::format("{}: cameras: {} cameras, at most {}", path, items.size(), CameraRig::kMaxCameras));
  std::optional<KalibrChain> chain;
  if (!rig.camchain.empty() && fs::is_regular_file(rig.camchain)) {
    chain.emplace(rig.camchain, &problems);
    if (chain->loaded() && !chain_base.from_imu) chain->check_kalibr_order();
  }
  int chain_cameras = 0;

  std::map<int, size_t> ids;
  std::map<std::string, std::string> channels;  // channel -> "cameras[i].channels.x"
  for (size_t i = 0; i < items.size() && static_cast<int>(i) < CameraRig::kMaxCameras; ++i) {
    const std::string prefix = fmt::format("cameras[{}].", i);
    common::YamlMappingReader r(path, items[i], prefix, &problems);
    RigCamera cam;
    cam.camera.visit(r);
    const std::string mount_key = read_mount(r, "", cam.extrinsics);
    r("channels.image", cam.image_channel, "image_t channel");
    r("channels.detections", cam.detections_channel, "detections_t channel");
    r("channels.windows", cam.windows_channel, "track_windows_t channel");
    r.finish(" (a rig camera takes camera.*, extrinsics.*, mount.yaw_deg, mount.pitch_deg, channels.*)");

    for (const std::string& line : cam.camera.validate()) r.validation_problem(line);
    if (!cam.camera.calibration.empty()) {
      fs::path calib(cam.camera.calibration);
      if (calib.is_relative()) calib = folder / calib;
      if (!fs::is_regular_file(calib))
        r.problem(
            "camera.calibration",
            fmt::format("'{}' is not a file (a relative path is taken from the rig file's folder)", calib.string()));
      cam.camera.calibration = calib.string();
    } else if (r.has("camera.kalibr_camera")) {
      r.problem("camera.kalibr_camera", "names a Kalibr camera, but camera.calibration is empty (an ideal pinhole)");
    }

    if (!rig.camchain.empty() && !cam.camera.calibration.empty() && same_file(cam.camera.calibration, rig.camchain)) {
      ++chain_cameras;
      const std::string entry_key = r.has("camera.kalibr_camera") ? "camera.kalibr_camera" : "camera.calibration";
      if (!mount_key.empty()) {
        r.problem(mount_key,
                  "this camera's mount comes from the camchain (its camera.calibration is camchain.file): "
                  "give no mount.* or extrinsics.* here");
      } else if (chain && chain->loaded()) {
        const int index = chain->find(cam.camera.kalibr_camera);
        if (index < 0) {
          r.problem(entry_key, fmt::format("'{}' is not in the camchain {} (its cameras: {})", cam.camera.kalibr_camera,
                                           rig.camchain, chain->names()));
        } else if (const auto T = chain_camera_to_body(*chain, chain_base, static_cast<size_t>(index),
                                                       fmt::format("cameras[{}]", i))) {
          cam.extrinsics.R_cam_to_body = row_major(T->linear());
          cam.extrinsics.p_cam_in_body = {T->translation().x(), T->translation().y(), T->translation().z()};
          for (const std::string& line : cam.extrinsics.validate())
            r.problem(entry_key, "the mount composed from the camchain is invalid: " + line);
        }
      }
    }

    const int id = cam.camera.camera_id;
    if (const auto it = ids.find(id); it != ids.end())
      r.problem("camera.camera_id", fmt::format("{} is also cameras[{}]'s", id, it->second));
    else
      ids[id] = i;
    if (cam.image_channel.empty()) cam.image_channel = fmt::format("IMAGE_CAM{}", id);
    if (cam.detections_channel.empty()) cam.detections_channel = fmt::format("DETECTIONS_CAM{}", id);
    if (cam.windows_channel.empty()) cam.windows_channel = fmt::format("WINDOWS_CAM{}", id);
    const std::pair<const char*, const std::string*> named[] = {{"channels.image", &cam.image_channel},
                                                                {"channels.detections", &cam.detections_channel},
                                                                {"channels.windows", &cam.windows_channel}};
    for (const auto& [key, channel] : named) {
      const auto [it, inserted] = channels.emplace(*channel, prefix + key);
      if (!inserted) r.problem(key, fmt::format("'{}' is also {}", *channel, it->second));
    }
    rig.cameras.push_back(std::move(cam));
  }
  if (chain) chain->finish();
  if (!rig.camchain.empty() && chain_cameras == 0 && !items.empty())
    top.problem("camchain.file", "no camera's camera.calibration is this file, so no mount comes from it");
  if (!problems.empty()) {
    std::string message =
        fmt::format("{}: {} problem{} in the camera rig:", path, problems.size(), problems.size() == 1 ? "" : "s");
    for (const std::string& p : problems) message += "\n  " + p;
    throw common::ConfigError(message);
  }
  return rig;
}

}  // namespace wingman::geometry
