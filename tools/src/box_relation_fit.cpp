// SPDX-License-Identifier: MIT
// `wingman model box-relation`: detector boxes against the exact bounding-sphere boxes of rendered targets.
#include "wingman/tools/box_relation_fit.hpp"

#include <wingman/common/config.hpp>
#include <wingman/common/progress.hpp>
#include <wingman/detector/box.hpp>
#include <wingman/detector/detector_options.hpp>
#include <wingman/detector/input_size.hpp>
#include <wingman/detector/model_loader.hpp>
#include <wingman/detector/sized_detector.hpp>
#include <wingman/detector/track_windows.hpp>
#include <wingman/geometry/camera_model.hpp>
#include <wingman/localizer/sphere_localizer.hpp>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>
#include <stdexcept>

namespace wingman::tools {
namespace {

namespace fs = std::filesystem;

/// One rendered target and the detector's box on it.
struct Sample {
  std::string airframe;
  double range_m = 0, radius_m = 0;
  double frame_radius_m = 0;  ///< without propellers; 0: the render did not say
  double elevation_deg = 0;   ///< the camera seen from the target: above (+) or below (-) its horizontal plane
  double det_w = 0, det_h = 0, image_w = 0;
  double sphere_w = 0, sphere_h = 0, sphere_cx = 0, sphere_cy = 0;
  double width_ratio = 0, height_ratio = 0;           // detected / sphere box
  int8_t pass = localizer::BoxRelation::kPassSingle;  ///< detection_t's PASS_ constant of the box
  geometry::PixelBox det;
  std::string image;  ///< the render's image, relative to the set's folder
  /// range / true range - 1 under the relation fitted or checked (exact localizer); NaN: no range (behind the camera)
  double range_error = std::numeric_limits<double>::quiet_NaN();
  std::shared_ptr<const geometry::CameraModel> camera;
};

geometry::Distortion distortion_of(const std::string& name, const std::string& file) {
  if (name == "none") return geometry::Distortion::kNone;
  if (name == "plumb_bob") return geometry::Distortion::kRadTan;
  if (name == "rational_polynomial") return geometry::Distortion::kRationalPolynomial;
  if (name == "equidistant") return geometry::Distortion::kEquidistant;
  throw std::runtime_error(fmt::format("{}: camera.distortion_model '{}' is not one the localizer knows", file, name));
}

double median(std::vector<double> v) {
  if (v.empty()) return 0;
  const size_t k = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<ptrdiff_t>(k), v.end());
  double m = v[k];
  if (v.size() % 2 == 0) m = 0.5 * (m + *std::max_element(v.begin(), v.begin() + static_cast<ptrdiff_t>(k)));
  return m;
}

RangeErrorStats stats_of(const std::vector<double>& e) {
  RangeErrorStats s;
  s.n = static_cast<int64_t>(e.size());
  if (e.empty()) return s;
  s.median = median(e);
  std::vector<double> dev, abs_e;
  for (double x : e) dev.push_back(std::abs(x - s.median)), abs_e.push_back(std::abs(x));
  s.mad = 1.4826 * median(dev);
  std::sort(abs_e.begin(), abs_e.end());
  s.p90_abs = abs_e[std::min(abs_e.size() - 1, static_cast<size_t>(0.9 * static_cast<double>(abs_e.size())))];
  return s;
}

geometry::PixelBox read_box(const nlohmann::json& n) {
  return {n.at("cx").get<double>(), n.at("cy").get<double>(), n.at("w").get<double>(), n.at("h").get<double>()};
}

/// Relative range error of a sample under `relation`: the exact localizer with the true camera and radius.
std::optional<double> range_error(const Sample& s, const localizer::BoxRelation& relation) {
  localizer::SphereLocalizerOptions o;
  o.radius_m = s.radius_m;
  o.box_relation = "sphere";
  o.min_range_m = s.radius_m * 1.01;
  o.max_range_m = 1e4;
  const localizer::LocalizeResult r =
      localizer::localize_box(s.det, *s.camera, o, relation.at(s.det_w, s.det_h, s.image_w, s.pass));
  if (!r.ok || !r.measurement.range_valid) return std::nullopt;
  return r.measurement.range / s.range_m - 1.0;
}

std::string range_bin(double range_m) {
  static const double edges[] = {2, 5, 10, 15, 20, 30, 40};
  for (size_t i = 0; i + 1 < std::size(edges); ++i)
    if (range_m < edges[i + 1]) return fmt::format("{:>2g}-{:g} m", edges[i], edges[i + 1]);
  return "40+ m";
}

/// The size a grid bins a sample by: the main grid its width / image width, the window grid its width in pixels.
double grid_size(const Sample& s) {
  return s.pass == localizer::BoxRelation::kPassWindow ? s.det_w : s.det_w / s.image_w;
}

/// A fitted grid: per bin the median ratios; sparse bins take the nearest size bin of the same aspect with data, else
/// the pooled median of that size, else of everything. range_sigma_rel is left 0 (set from the residuals later).
localizer::BoxRelation::Grid fit_grid(const std::vector<double>& size_edges, const std::vector<double>& aspect_edges,
                                      int min_bin_count, const std::vector<Sample>& samples) {
  localizer::BoxRelation::Grid t;
  t.size_edges = size_edges;
  t.aspect_edges = aspect_edges;
  const size_t n = t.size_edges.size() - 1, m = t.aspect_edges.size() - 1;
  std::vector<std::vector<double>> kw(n * m), kh(n * m), kw_size(n), kh_size(n);
  std::vector<double> kw_all, kh_all;
  for (const Sample& s : samples) {
    const double size = grid_size(s);
    const size_t i = t.size_bin(size), c = t.cell(size, s.det_h / s.det_w);
    kw[c].push_back(s.width_ratio), kh[c].push_back(s.height_ratio);
    kw_size[i].push_back(s.width_ratio), kh_size[i].push_back(s.height_ratio);
    kw_all.push_back(s.width_ratio), kh_all.push_back(s.height_ratio);
  }
  const auto enough = [&](size_t c) { return static_cast<int>(kw[c].size()) >= min_bin_count; };
  t.width_ratio.assign(n * m, 0), t.height_ratio.assign(n * m, 0), t.count.assign(n * m, 0);
  t.range_sigma_rel.assign(n * m, 0);
  for (size_t i = 0; i < n; ++i) {
    for (size_t a = 0; a < m; ++a) {
      const size_t c = i * m + a;
      t.count[c] = static_cast<int>(kw[c].size());
      size_t src = c;
      if (!enough(c)) {
        src = n * m;  // none yet
        for (size_t d = 1; d < n && src == n * m; ++d) {
          if (i >= d && enough((i - d) * m + a))
            src = (i - d) * m + a;
          else if (i + d < n && enough((i + d) * m + a))
            src = (i + d) * m + a;
        }
        if (!enough(c)) t.count[c] = 0;
      }
      if (src < n * m) {
        t.width_ratio[c] = median(kw[src]), t.height_ratio[c] = median(kh[src]);
      } else if (static_cast<int>(kw_size[i].size()) >= min_bin_count) {
        t.width_ratio[c] = median(kw_size[i]), t.height_ratio[c] = median(kh_size[i]);
      } else {
        t.width_ratio[c] = median(kw_all), t.height_ratio[c] = median(kh_all);
      }
    }
  }
  return t;
}

}  // namespace

std::string BoxRelationSummary::markdown() const {
  std::string s = fmt::format(
      "{} images: {} targets found by the detector (IoU with the outline box >= the threshold), {} not found, {} "
      "skipped (cut by the image border){}{}\n\n",
      images, matched, unmatched, skipped_truncated,
      not_searched > 0 ? fmt::format(", {} not searched by a window (the single pass sees them well)", not_searched)
                       : std::string(),
      no_target > 0 ? fmt::format(", {} without a drone", no_target) : std::string());
  s += fmt::format("Range error (range / true range - 1), the airframe's true bounding radius, exact localizer:\n\n");
  s += "| boxes | n | sphere (ratio 1): median | MAD | " + relation_name + ": median | MAD | |error| p90 |\n";
  s += "|---|---|---|---|---|---|---|\n";
  const auto row = [&](const std::string& name, const RangeErrorStats& a, const RangeErrorStats& b) {
    return fmt::format("| {} | {} | {:+.3f} | {:.3f} | {:+.3f} | {:.3f} | {:.3f} |\n", name, b.n, a.median, a.mad,
                       b.median, b.mad, b.p90_abs);
  };
  s += row("all", sphere_all, relation_all);
  for (const auto& [name, st] : relation_by_airframe) {
    const auto it = sphere_by_airframe.find(name);
    s += row(name, it == sphere_by_airframe.end() ? RangeErrorStats{} : it->second, st);
  }
  s +=
      "\nBy true range (" + relation_name + "):\n\n| range | n | median | MAD | |error| p90 |\n|---|---|---|---|---|\n";
  for (const auto& [name, st] : relation_by_range)
    s += fmt::format("| {} | {} | {:+.3f} | {:.3f} | {:.3f} |\n", name, st.n, st.median, st.mad, st.p90_abs);
  return s;
}

BoxRelationSummary run_box_relation(const BoxRelationRequest& rq, std::ostream& progress) {
  if (rq.data.empty()) throw std::invalid_argument("--data: a `wingman dataset synth` folder is required");
  if (rq.check.empty() && rq.out.empty())
    throw std::invalid_argument("--out FILE (fit) or --check RELATION is required");
  if (rq.pass != "single" && rq.pass != "window")
    throw std::invalid_argument(fmt::format("--pass {}: expected single or window", rq.pass));
  const bool window_pass = rq.pass == "window";
  if (rq.min_iou <= 0 || rq.min_iou > 1)
    throw std::invalid_argument(fmt::format("--min-iou {}: expected (0, 1]", rq.min_iou));
  const fs::path meta_dir = fs::path(rq.data) / "meta" / rq.split;
  if (!fs::is_directory(meta_dir))
    throw std::runtime_error(
        fmt::format("{}: no such folder (expected a `wingman dataset synth` set)", meta_dir.string()));
  std::vector<fs::path> metas;
  for (const auto& e : fs::directory_iterator(meta_dir))
    if (e.path().extension() == ".json") metas.push_back(e.path());
  std::sort(metas.begin(), metas.end());
  if (rq.max_images > 0 && metas.size() > static_cast<size_t>(rq.max_images))
    metas.resize(static_cast<size_t>(rq.max_images));
  if (metas.empty()) throw std::runtime_error(meta_dir.string() + ": no .json metadata");

  detector::DetectorOptions dopt;
  if (!rq.detector_config.empty()) dopt = common::load_options<detector::DetectorOptions>(rq.detector_config);
  const std::string model_id = detector::weights_model_id(dopt.weights);
  auto make_backend = [&](const detector::DarknetModel& sized) {
    return detector::make_backend(dopt.backend, sized, dopt.opencl, 1, nullptr, detector::AutoChoice::kRepeatable);
  };
  detector::SizedDetector pipeline(dopt.detection, detector::load_model(dopt.cfg, dopt.weights),
                                   *detector::InputSize::parse(dopt.input_size), make_backend);
  // --pass window: each target searched as the tracker-driven windows search a tracked drone (a window on its
  // outline box, 2 px of doubt), whether or not the configuration enables them; only the window's boxes count.
  std::unique_ptr<detector::WindowDetector> windows;
  if (window_pass)
    windows = std::make_unique<detector::WindowDetector>(dopt.windows, dopt.detection,
                                                         detector::load_model(dopt.cfg, dopt.weights), make_backend);
  // The boxes to match, or nullopt when the windows would not search this target.
  auto detect = [&](const cv::Mat& bgr,
                    const geometry::PixelBox& outline) -> std::optional<std::vector<detector::Box>> {
    if (!windows) return pipeline.detect(bgr);
    wingman::track_windows_t m{};
    m.camera_id = 0;
    m.image_width = bgr.cols;
    m.image_height = bgr.rows;
    wingman::track_window_t w{};
    w.cx = static_cast<float>(outline.cx), w.cy = static_cast<float>(outline.cy);
    w.w = static_cast<float>(outline.w), w.h = static_cast<float>(outline.h);
    w.sigma_px = 2.0f;
    w.confirmed = true;
    m.windows = {w};
    m.num_windows = 1;
    const cv::Size size(bgr.cols, bgr.rows);
    const auto search = detector::windows_to_search(m, 0, size, 0, pipeline.net_px_per_image_px(size), dopt.windows);
    if (search.empty()) return std::nullopt;
    return windows->detect(bgr, {}, search);
  };

  BoxRelationSummary summary;
  std::vector<Sample> samples;
  common::Progress images("wingman model box-relation", static_cast<int64_t>(metas.size()), "images", &progress);
  for (size_t k = 0; k < metas.size(); ++k) {
    images.update(static_cast<int64_t>(k), fmt::format("{} targets found", summary.matched));  // `continue`s below
    const std::string file = metas[k].string();
    nlohmann::json meta;
    try {
      std::ifstream in(file);
      if (!in) throw std::runtime_error("cannot open the file");
      meta = nlohmann::json::parse(in);
    } catch (const std::exception& e) {
      throw std::runtime_error(fmt::format("{}: not readable JSON: {}", file, e.what()));
    }
    ++summary.images;
    try {
      if (!meta.contains("target") && meta.contains("distractors")) {  // a negative: distractors only
        ++summary.no_target;
        continue;
      }
      if (!meta.contains("sphere_box") || meta["sphere_box"].is_null())
        throw std::runtime_error("sphere_box: missing (render the set with this version of `wingman dataset synth`)");
      if (meta.at("box").at("truncated").get<bool>()) {
        ++summary.skipped_truncated;
        continue;
      }
      const int W = meta.at("width").get<int>(), H = meta.at("height").get<int>();
      const geometry::PixelBox sphere = read_box(meta["sphere_box"]), outline = read_box(meta["box"]);
      if (sphere.cx - sphere.w / 2 < 1 || sphere.cx + sphere.w / 2 > W - 1 || sphere.cy - sphere.h / 2 < 1 ||
          sphere.cy + sphere.h / 2 > H - 1) {
        ++summary.skipped_truncated;  // the sphere's box leaves the image: no whole ratio
        continue;
      }
      const nlohmann::json& cam = meta.at("camera");
      const std::string distortion = cam.at("distortion_model").get<std::string>();
      auto camera = std::make_shared<const geometry::CameraModel>(
          W, H, cam.at("fx").get<double>(), cam.at("fy").get<double>(), cam.at("cx").get<double>(),
          cam.at("cy").get<double>(), distortion_of(distortion, file),
          distortion == "none" ? std::vector<double>{} : cam.at("coefficients").get<std::vector<double>>());
      const std::string image = (fs::path(rq.data) / meta.at("image").get<std::string>()).string();
      const cv::Mat bgr = cv::imread(image, cv::IMREAD_COLOR);
      if (bgr.empty()) throw std::runtime_error(image + ": cannot read the image");
      double best = 0;
      geometry::PixelBox det;
      detector::Box truth;
      truth.cx = static_cast<float>(outline.cx), truth.cy = static_cast<float>(outline.cy);
      truth.w = static_cast<float>(outline.w), truth.h = static_cast<float>(outline.h);
      const auto boxes = detect(bgr, outline);
      if (!boxes) {
        ++summary.not_searched;
        continue;
      }
      detector::Pass pass = detector::Pass::kSingle;
      for (const detector::Box& b : *boxes) {
        if (b.class_id != 0) continue;
        if (window_pass && b.pass != detector::Pass::kWindow) continue;
        if (const double o = detector::iou(b, truth); o > best) best = o, det = {b.cx, b.cy, b.w, b.h}, pass = b.pass;
      }
      if (best < rq.min_iou) {
        ++summary.unmatched;
        continue;
      }
      ++summary.matched;
      Sample s;
      const nlohmann::json& target = meta.at("target");
      const std::string airframe = target.at("airframe").get<std::string>();
      s.airframe = airframe.find('.') != std::string::npos ? airframe : "procedural " + airframe;
      s.range_m = target.at("range_m").get<double>();
      s.radius_m = target.at("bounding_radius_m").get<double>();
      if (target.contains("frame_radius_m")) s.frame_radius_m = target["frame_radius_m"].get<double>();
      {
        const auto pc = meta.at("T_cam_to_world").at("p").get<std::vector<double>>();
        const auto pt = target.at("T_body_to_world").at("p").get<std::vector<double>>();
        if (pc.size() != 3 || pt.size() != 3)
          throw std::invalid_argument("T_cam_to_world.p, T_body_to_world.p: 3 numbers");
        const double dx = pc[0] - pt[0], dy = pc[1] - pt[1], dz = pc[2] - pt[2];
        s.elevation_deg = std::atan2(dz, std::hypot(dx, dy)) * 180.0 / M_PI;
      }
      s.det = det, s.det_w = det.w, s.det_h = det.h, s.image_w = W;
      // A zoom-in box is the main grid's like a single-pass one.
      s.pass =
          pass == detector::Pass::kWindow ? localizer::BoxRelation::kPassWindow : localizer::BoxRelation::kPassSingle;
      s.sphere_w = sphere.w, s.sphere_h = sphere.h, s.sphere_cx = sphere.cx, s.sphere_cy = sphere.cy;
      s.width_ratio = det.w / sphere.w, s.height_ratio = det.h / sphere.h;
      s.image = meta.at("image").get<std::string>();
      s.camera = camera;
      samples.push_back(std::move(s));
    } catch (const nlohmann::json::exception& e) {
      throw std::runtime_error(fmt::format("{}: {}", file, e.what()));
    } catch (const std::invalid_argument& e) {
      throw std::runtime_error(fmt::format("{}: {}", file, e.what()));
    }
  }
  images.update(static_cast<int64_t>(metas.size()), fmt::format("{} targets found", summary.matched));
  images.finish();
  if (samples.empty()) throw std::runtime_error("the detector found none of the targets: nothing to measure");
  localizer::BoxRelation relation;
  if (!rq.check.empty()) {
    relation = localizer::BoxRelation::load(rq.check);
    if (const std::string bad = relation.check_model(model_id); !bad.empty()) throw std::runtime_error(bad);
  } else if (window_pass) {
    // The base relation with its window grid fitted here.
    const localizer::BoxRelation base = localizer::BoxRelation::load(rq.base);
    if (base.is_sphere()) throw std::invalid_argument("--base sphere: the window grid needs a model's relation");
    if (const std::string bad = base.check_model(model_id); !bad.empty())
      throw std::runtime_error("--base " + rq.base + ": " + bad);
    localizer::BoxRelation::Table table = base.table();
    table.window = fit_grid(rq.window_size_edges, rq.aspect_edges, rq.min_bin_count, samples);
    table.model_id = model_id;
    table.measured_with = base.table().measured_with + "; " + rq.command_line;
    relation = localizer::BoxRelation::from_table(table, rq.out);
  } else {
    localizer::BoxRelation::Table table;
    static_cast<localizer::BoxRelation::Grid&>(table) =
        fit_grid(rq.size_edges, rq.aspect_edges, rq.min_bin_count, samples);
    table.model = rq.model_name;
    table.measured_with = rq.command_line;
    table.edge_noise_rel = rq.edge_noise_rel;
    table.model_id = model_id;
    relation = localizer::BoxRelation::from_table(table, rq.out);
  }
  summary.relation_name = rq.check.empty() ? "fitted" : relation.name();

  // Errors per sample; the fitted table's range_sigma_rel from the residuals in each bin.
  const localizer::BoxRelation sphere = localizer::BoxRelation::sphere();
  std::vector<double> e_sphere_all, e_rel_all;
  std::map<std::string, std::vector<double>> e_sphere_af, e_rel_af, e_rel_range;
  // Fitting: the grid fitted (the window grid with --pass window), its residuals per bin.
  const bool fitting = rq.check.empty();
  const localizer::BoxRelation::Grid& tb =
      window_pass ? relation.table().window : static_cast<const localizer::BoxRelation::Grid&>(relation.table());
  std::vector<std::vector<double>> residual_by_bin(fitting ? (tb.size_edges.size() - 1) * (tb.aspect_edges.size() - 1)
                                                           : 0);
  for (Sample& s : samples) {
    const auto es = range_error(s, sphere);
    const auto er = range_error(s, relation);
    if (!es || !er) continue;
    s.range_error = *er;
    e_sphere_all.push_back(*es), e_sphere_af[s.airframe].push_back(*es);
    e_rel_all.push_back(*er), e_rel_af[s.airframe].push_back(*er), e_rel_range[range_bin(s.range_m)].push_back(*er);
    if (!residual_by_bin.empty()) residual_by_bin[tb.cell(grid_size(s), s.det_h / s.det_w)].push_back(*er);
  }
  summary.sphere_all = stats_of(e_sphere_all), summary.relation_all = stats_of(e_rel_all);
  for (const auto& [k, v] : e_sphere_af) summary.sphere_by_airframe[k] = stats_of(v);
  for (const auto& [k, v] : e_rel_af) summary.relation_by_airframe[k] = stats_of(v);
  for (const auto& [k, v] : e_rel_range) summary.relation_by_range[k] = stats_of(v);

  if (!rq.samples_csv.empty()) {
    std::ofstream csv(rq.samples_csv);
    if (!csv) throw std::runtime_error(rq.samples_csv + ": cannot write the samples (--samples)");
    csv << "airframe,range_m,radius_m,frame_radius_m,elevation_deg,image_w,det_w,det_h,sphere_w,sphere_h,width_ratio,"
           "height_ratio,range_error,image,det_cx,det_cy,sphere_cx,sphere_cy\n";
    for (const Sample& s : samples)
      csv << fmt::format(
          "\"{}\",{:.4f},{:.4f},{:.4f},{:.2f},{:g},{:.3f},{:.3f},{:.3f},{:.3f},{:.5f},{:.5f},{:.5f},\"{}\",{:.3f},{:."
          "3f},"
          "{:.3f},{:.3f}\n",
          s.airframe, s.range_m, s.radius_m, s.frame_radius_m, s.elevation_deg, s.image_w, s.det_w, s.det_h, s.sphere_w,
          s.sphere_h, s.width_ratio, s.height_ratio, s.range_error, s.image, s.det.cx, s.det.cy, s.sphere_cx,
          s.sphere_cy);
    if (!csv) throw std::runtime_error(rq.samples_csv + ": write failed (--samples)");
  }

  if (fitting) {
    localizer::BoxRelation::Table table = relation.table();
    localizer::BoxRelation::Grid& fitted = window_pass ? table.window : table;
    // The spread of the range left in each bin: its residuals' 1.4826 MAD about zero (a bin's median stays in the
    // spread); sparse bins take the spread of all boxes.
    std::vector<double> abs_all;
    for (double e : e_rel_all) abs_all.push_back(std::abs(e));
    const double all_sigma = 1.4826 * median(abs_all);
    for (size_t c = 0; c < residual_by_bin.size(); ++c) {
      std::vector<double> a;
      for (double e : residual_by_bin[c]) a.push_back(std::abs(e));
      fitted.range_sigma_rel[c] = static_cast<int>(a.size()) >= rq.min_bin_count ? 1.4826 * median(a) : all_sigma;
    }
    relation = localizer::BoxRelation::from_table(table, rq.out);
    const std::string header =
        window_pass
            ? fmt::format(
                  "How {} ({}) draws boxes relative to the target's bounding sphere (docs/localization.md, \"Box "
                  "relation\"). The\n"
                  "main grid is {}'s (measured_with: its first command). The window grid, measured by `wingman model "
                  "box-relation\n"
                  "--pass window` on {} targets found by a tracker-driven window in {} rendered images: range error of "
                  "the window\n"
                  "boxes with the airframe's true radius: ratio 1 median {:+.3f}, this relation {:+.3f} (MAD {:.3f}).",
                  rq.model_name, model_id, rq.base, summary.matched, summary.images, summary.sphere_all.median,
                  summary.relation_all.median, summary.relation_all.mad)
            : fmt::format(
                  "How {} ({}) draws boxes relative to the target's bounding sphere, measured by `wingman model "
                  "box-relation`\n"
                  "on {} targets found in {} rendered images (docs/localization.md, \"Box relation\"). The localizer "
                  "reads it "
                  "as\n"
                  "target.box_relation. Range error on these images with the airframe's true radius: ratio 1 median "
                  "{:+.3f},\n"
                  "this relation {:+.3f} (MAD {:.3f}).",
                  rq.model_name, model_id, summary.matched, summary.images, summary.sphere_all.median,
                  summary.relation_all.median, summary.relation_all.mad);
    if (const fs::path parent = fs::path(rq.out).parent_path(); !parent.empty()) fs::create_directories(parent);
    std::ofstream f(rq.out);
    f << relation.to_yaml(header);
    f.close();
    if (!f) throw std::runtime_error(rq.out + ": cannot write the relation");
  }
  return summary;
}

}  // namespace wingman::tools
