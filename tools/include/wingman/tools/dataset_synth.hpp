// SPDX-License-Identifier: MIT
// `wingman dataset synth`: rendered, labelled training images with domain randomization, in the YOLO layout.
#pragma once

#include <wingman/sim/render_options.hpp>

#include <cstdint>
#include <memory>
#include <ostream>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace wingman::tools {

/// What `wingman dataset synth` randomizes, and within which ranges (config keys under "synth."; the base scene
/// and sensor under "render."). Every image draws its own camera pose, target airframe and pose, scene, lighting
/// and sensor effects from these ranges.
struct DatasetSynthConfig {
  int width = 1280;  ///< image width, pixels
  int height = 720;  ///< image height, pixels
  int cameras = 4;   ///< random camera models (intrinsics and distortion) per run; each image uses one of them
  double hfov_min_deg = 45.0;     ///< horizontal field of view of the random cameras, degrees
  double hfov_max_deg = 100.0;    ///< (hfov_min_deg..hfov_max_deg)
  double fisheye_fraction = 0.2;  ///< share of cameras with an equidistant (fisheye) lens; the others are radtan
  double radtan_k1_min = -0.35;   ///< radtan k1 range (barrel < 0 < pincushion); k2 follows as about -0.3 k1
  double radtan_k1_max = 0.1;
  double range_min_m = 1.0;  ///< camera-to-target distance, metres, drawn log-uniformly
  double range_max_m = 60.0;
  double mesh_fraction = 0.5;  ///< share of targets that are meshes from --meshes (when any are given)
  double scale_min = 0.6;      ///< procedural airframes: size relative to the F450-like default (log-uniform)
  double scale_max = 2.0;
  double disc_fraction = 0.3;        ///< share of procedural airframes with translucent propeller discs
  double camera_height_min_m = 1.5;  ///< camera height above the ground, metres
  double camera_height_max_m = 120.0;
  double camera_pitch_min_deg = -45.0;  ///< camera pitch (positive: looking up), degrees
  double camera_pitch_max_deg = 40.0;
  double camera_roll_max_deg = 10.0;   ///< camera roll within +-this, degrees
  double target_tilt_max_deg = 30.0;   ///< target roll and pitch within +-this, degrees (yaw is free)
  double blur_fraction = 0.3;          ///< share of images with motion blur
  double blur_exposure_max_s = 0.012;  ///< motion-blur shutter time up to this, seconds
  double noise_std_max = 4.0;          ///< read noise std drawn in 0..this, 8-bit levels
  double shot_noise_max = 1.0;         ///< photon noise drawn in 0..this
  double exposure_jitter = 0.3;        ///< log-normal sigma of the per-image exposure gain
  double val_fraction = 0.1;           ///< share of images in the val split
  std::string image_format = "png";    ///< png (lossless) or jpg
  int jpeg_quality = 95;               ///< jpg quality, 1..100
  int min_visible_pixels = 12;         ///< a drone seen at fewer pixel centres is drawn again elsewhere
  /// Share of images whose target flies at about the camera's height: seen within +-horizon_elevation_max_deg of
  /// the horizontal, i.e. on the horizon, often against the treeline (the view of a follower in formation). The
  /// other targets are anywhere in the image. 0 draws exactly the images of earlier versions.
  double horizon_fraction = 0.0;
  double horizon_elevation_max_deg = 3.0;  ///< elevation of those targets seen from the camera, within +-this, degrees
  /// Distractors per image (sim::distractor_model: procedural airplanes, birds and helicopters, each kind equally
  /// likely): between 0 and this many, uniform, placed anywhere in the image in front of the sky or the ground. They
  /// draw from a random stream of their own: the drone, camera and scene of each image stay those of a run without
  /// them (unless one hides the drone: the placement is then drawn again), and 0 (with negative_fraction 0) draws
  /// exactly the images of earlier versions.
  int distractors_max = 0;
  /// Their apparent size, wing span or rotor diameter in pixels (fx x span / range), log-uniform in
  /// [distractor_px_min, distractor_px_max]; the range follows from the kind's span (airplanes 9-60 m, birds
  /// 0.25-1.8 m, helicopter rotors 8-16 m) and stays under 4 km (the renderer's far plane is 5 km).
  double distractor_px_min = 6.0;
  double distractor_px_max = 80.0;
  /// Label them as classes 1 (airplane), 2 (bird), 3 (helicopter), as the Halmstad import's --distractor-classes
  /// does (data.yaml names four classes); false: left unlabelled, hard negatives for a one-class detector. A
  /// distractor is labelled when seen at min_visible_pixels pixel centres or more.
  bool distractor_classes = false;
  /// Share of images without a drone: 1 to distractors_max distractors only, at least one of them seen at
  /// min_visible_pixels (their metadata has no "target"). Needs distractors_max >= 1.
  double negative_fraction = 0.0;
  sim::RenderOptions render;  ///< base scene and sensor options (render.*)

  template <class V>
  void visit(V& v) {
    v("synth.width", width, "image width, pixels");
    v("synth.height", height, "image height, pixels");
    v("synth.cameras", cameras, "random camera models per run (each image uses one)");
    v("synth.hfov_min_deg", hfov_min_deg, "horizontal field of view, lower end, degrees");
    v("synth.hfov_max_deg", hfov_max_deg, "horizontal field of view, upper end, degrees");
    v("synth.fisheye_fraction", fisheye_fraction, "share of cameras with an equidistant (fisheye) lens");
    v("synth.radtan_k1_min", radtan_k1_min, "radtan k1, lower end (barrel distortion < 0)");
    v("synth.radtan_k1_max", radtan_k1_max, "radtan k1, upper end");
    v("synth.range_min_m", range_min_m, "camera-to-target distance, lower end, metres (log-uniform)");
    v("synth.range_max_m", range_max_m, "camera-to-target distance, upper end, metres");
    v("synth.mesh_fraction", mesh_fraction, "share of targets drawn from --meshes (when given)");
    v("synth.scale_min", scale_min, "procedural airframe size relative to an F450, lower end");
    v("synth.scale_max", scale_max, "procedural airframe size relative to an F450, upper end");
    v("synth.disc_fraction", disc_fraction, "share of procedural airframes with translucent propeller discs");
    v("synth.camera_height_min_m", camera_height_min_m, "camera height above ground, lower end, metres");
    v("synth.camera_height_max_m", camera_height_max_m, "camera height above ground, upper end, metres");
    v("synth.camera_pitch_min_deg", camera_pitch_min_deg, "camera pitch, lower end, degrees (up > 0)");
    v("synth.camera_pitch_max_deg", camera_pitch_max_deg, "camera pitch, upper end, degrees");
    v("synth.camera_roll_max_deg", camera_roll_max_deg, "camera roll within +-this, degrees");
    v("synth.target_tilt_max_deg", target_tilt_max_deg, "target roll and pitch within +-this, degrees");
    v("synth.blur_fraction", blur_fraction, "share of images with motion blur");
    v("synth.blur_exposure_max_s", blur_exposure_max_s, "motion-blur shutter time, upper end, seconds");
    v("synth.noise_std_max", noise_std_max, "read noise std, upper end, 8-bit levels");
    v("synth.shot_noise_max", shot_noise_max, "photon noise, upper end");
    v("synth.exposure_jitter", exposure_jitter, "per-image exposure gain, log-normal sigma");
    v("synth.val_fraction", val_fraction, "share of images in the val split");
    v("synth.image_format", image_format, "png or jpg");
    v("synth.jpeg_quality", jpeg_quality, "jpg quality, 1..100");
    v("synth.min_visible_pixels", min_visible_pixels, "redraw a target seen at fewer pixel centres");
    v("synth.horizon_fraction", horizon_fraction, "share of targets at about the camera's height (on the horizon)");
    v("synth.horizon_elevation_max_deg", horizon_elevation_max_deg,
      "those targets' elevation seen from the camera, within +-this, degrees");
    v("synth.distractors_max", distractors_max,
      "airplanes, birds and helicopters per image: 0 to this many (0: none, the images of earlier versions)");
    v("synth.distractor_px_min", distractor_px_min, "distractor span in pixels, lower end (log-uniform)");
    v("synth.distractor_px_max", distractor_px_max, "distractor span in pixels, upper end");
    v("synth.distractor_classes", distractor_classes,
      "label distractors as classes 1 airplane, 2 bird, 3 helicopter (false: unlabelled negatives)");
    v("synth.negative_fraction", negative_fraction, "share of images without a drone, distractors only");
    render.visit(v);
  }
  /// Every problem, as "synth.key = value: rule" (and render.*), empty when valid.
  std::vector<std::string> validate() const;
};

/// One run of `wingman dataset synth`.
struct DatasetSynthRequest {
  std::string out_dir;              ///< the dataset folder; must not hold images already
  int count = 0;                    ///< images to render (> 0)
  uint64_t seed = 1;                ///< the same seed, config and meshes give the same bytes
  std::string config;               ///< YAML with synth.* and render.* keys ("" = defaults)
  std::vector<std::string> meshes;  ///< mesh files, or folders of them (.glb .gltf .obj .dae .stl .ply .fbx)
};

/// What a run wrote.
struct DatasetSynthSummary {
  std::string out_dir;
  int images = 0;     ///< images written (each with one drone label, but the negatives)
  int train = 0;      ///< of which in images/train
  int val = 0;        ///< of which in images/val
  int negatives = 0;  ///< of which without a drone (synth.negative_fraction)
  int redrawn = 0;  ///< placements drawn again because the drone (a negative: every distractor) was not visible enough
  int distractors = 0;           ///< distractors rendered
  int distractors_labelled = 0;  ///< of which labelled (synth.distractor_classes, seen at min_visible_pixels)
  double seconds = 0.0;
  /// "wrote 1000 images (900 train, 100 val) to DIR in 812.3 s (1.23 images/s, 57 placements redrawn)", and with
  /// distractors ", 1480 distractors (1020 labelled), 200 images without a drone".
  std::string one_line() const;
};

/// Renders the dataset:
///  - `images/{train,val}/NNNNNN.<png|jpg>`;
///  - `labels/{train,val}/NNNNNN.txt`: one line `0 cx cy w h` (YOLO: centre and size over the image size; the box is
///    the drone's exact projected box, sim::RenderedBox), none in a negative image; with synth.distractor_classes,
///    one line `k cx cy w h` per distractor seen well enough (k = sim::DistractorKind);
///  - `meta/{train,val}/NNNNNN.json`: camera model, camera pose, target airframe (its full DroneSpec, or mesh file)
///    and pose, position in the camera frame, range, box in pixels, exposure, blur and noise (a negative image has no
///    "target"); "distractors": each one's kind, class, DistractorSpec, pose, rotor angle, range, box and whether it
///    was labelled;
///  - `data.yaml` (path, train, val, nc: 1, names: [drone]; with synth.distractor_classes nc: 4, names: [drone,
///    airplane, bird, helicopter]).
/// Every image but the negatives shows one drone seen at min_visible_pixels pixel centres or more (distractors may
/// hide part of it): a placement where it is hidden or too small is drawn again (counted in `redrawn`), so only the
/// negatives lack a drone label; a negative is drawn again until one of its distractors is seen that well. Image i
/// depends only on the seed, the config, the meshes and i. Progress lines go to `progress` about once a second. Throws
/// common::ConfigError for a bad config, std::runtime_error naming the file or folder for I/O problems.
DatasetSynthSummary run_dataset_synth(const DatasetSynthRequest& request, std::ostream& progress);
/// The same with `config` (validated) in place of the file `request.config` (the CLI's layers: --config, --set).
DatasetSynthSummary run_dataset_synth(const DatasetSynthRequest& request, const DatasetSynthConfig& config,
                                      std::ostream& progress);

/// Adds `dataset synth` and `dataset from-log` to the CLI and runs the one chosen.
class DatasetVerbs {
 public:
  /// Registers `dataset` and its subcommands `synth` and `from-log` with their options on `app`.
  explicit DatasetVerbs(CLI::App& app);
  ~DatasetVerbs();

  /// After parsing: runs `dataset synth` or `dataset from-log` when chosen and returns its exit code (0 ok,
  /// 1 failure, 2 bad config or arguments), or -1 when neither was chosen. The summary goes to `out`, progress and
  /// errors to `err`.
  int run_if_chosen(std::ostream& out, std::ostream& err);

 private:
  struct State;
  std::unique_ptr<State> s_;
};

}  // namespace wingman::tools
