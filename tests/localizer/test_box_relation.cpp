// SPDX-License-Identifier: MIT
// The box relation (box_relation.hpp): lookup and interpolation, the file's errors, the model check, the shipped
// relation against the shipped weights, and what the ratios do to a localization.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <wingman/detector/model_loader.hpp>
#include <wingman/geometry/sphere_projection.hpp>
#include <wingman/localizer/box_relation.hpp>
#include <wingman/localizer/sphere_localizer.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

namespace wingman::localizer {
namespace {

using geometry::CameraModel;
using geometry::project_sphere;
using geometry::SphereImageBox;

/// Two size bins (centres at 0.02 and 0.08 of the image width: geometric means of the edges) and two aspect bins.
constexpr const char* kTwoByTwo = R"(box_relation:
  model: "test"
  model_id: "sha256:0123456789abcdef"
  edge_noise_rel: 0.1
  size_edges: [0.01, 0.04, 0.16]
  aspect_edges: [0.1, 0.6, 10]
  width_ratio: [0.6, 0.7, 0.8, 0.9]
  height_ratio: [0.5, 0.55, 0.75, 0.85]
  range_sigma_rel: [0.1, 0.2, 0.05, 0.06]
)";

/// kTwoByTwo with a window grid: sizes in image pixels, two size bins (centres 8 and 32 px) and one aspect bin.
const std::string kWithWindow = std::string(kTwoByTwo) + R"(  window:
    size_edges: [4, 16, 64]
    aspect_edges: [0.05, 20]
    width_ratio: [1.0, 0.75]
    height_ratio: [0.9, 0.6]
    range_sigma_rel: [0.3, 0.1]
    count: [12, 40]
)";

TEST(BoxRelation, TheSphereRelationIsRatioOneWithoutSpread) {
  const BoxScale s = BoxRelation::load("sphere").at(50, 50, 1280);
  EXPECT_EQ(s.width_ratio, 1.0);
  EXPECT_EQ(s.height_ratio, 1.0);
  EXPECT_EQ(s.range_sigma_rel, 0.0);
  EXPECT_EQ(s.edge_noise_rel, 0.0);
  EXPECT_TRUE(BoxRelation::sphere().is_sphere());
}

TEST(BoxRelation, BinsByAspectAndInterpolatesInLogWidthBetweenBinCentresHeldBeyond) {
  const BoxRelation r = BoxRelation::parse(kTwoByTwo, "two.yaml");
  const double W = 1000;
  // At the first size bin's centre (0.02 W = 20 px), aspect 0.5 (first bin) and 1.0 (second).
  EXPECT_NEAR(r.at(20, 10, W).width_ratio, 0.6, 1e-12);
  EXPECT_NEAR(r.at(20, 20, W).width_ratio, 0.7, 1e-12);
  EXPECT_NEAR(r.at(20, 20, W).height_ratio, 0.55, 1e-12);
  // Halfway in log between the centres (0.04 W): the mean of the two bins.
  EXPECT_NEAR(r.at(40, 40, W).width_ratio, 0.8, 1e-12);
  EXPECT_NEAR(r.at(40, 40, W).range_sigma_rel, 0.13, 1e-12);
  // Beyond the outer centres: held.
  EXPECT_NEAR(r.at(2, 2, W).width_ratio, 0.7, 1e-12);
  EXPECT_NEAR(r.at(900, 900, W).width_ratio, 0.9, 1e-12);
  EXPECT_NEAR(r.at(900, 9000, W).height_ratio, 0.85, 1e-12);  // aspect beyond the last edge: the last bin
  EXPECT_EQ(r.at(20, 20, W).edge_noise_rel, 0.1);
  EXPECT_EQ(r.model_id(), "sha256:0123456789abcdef");
}

TEST(BoxRelation, AWindowsBoxTakesTheWindowGridBySizeInImagePixelsAndOtherBoxesTheMainGrid) {
  const BoxRelation r = BoxRelation::parse(kWithWindow, "window.yaml");
  ASSERT_TRUE(r.has_window_grid());
  const double W = 1000;
  // 8 px: the window grid's first centre, whatever the image width; the same box of the single pass: the main grid's
  // first size bin (0.008 of the width, held below its centre), aspect 1: second aspect bin.
  EXPECT_NEAR(r.at(8, 8, W, BoxRelation::kPassWindow).width_ratio, 1.0, 1e-12);
  EXPECT_NEAR(r.at(8, 8, 4000, BoxRelation::kPassWindow).width_ratio, 1.0, 1e-12);
  EXPECT_NEAR(r.at(8, 8, W, BoxRelation::kPassWindow).height_ratio, 0.9, 1e-12);
  EXPECT_NEAR(r.at(8, 8, W, BoxRelation::kPassWindow).range_sigma_rel, 0.3, 1e-12);
  EXPECT_NEAR(r.at(8, 8, W, BoxRelation::kPassSingle).width_ratio, 0.7, 1e-12);
  EXPECT_NEAR(r.at(8, 8, W).width_ratio, 0.7, 1e-12);     // the default: a single-pass box
  EXPECT_NEAR(r.at(8, 8, W, 1).width_ratio, 0.7, 1e-12);  // a zoom-in box: the main grid
  // Halfway in log between the window centres (16 px): the mean; held beyond the last centre.
  EXPECT_NEAR(r.at(16, 16, W, BoxRelation::kPassWindow).width_ratio, 0.875, 1e-12);
  EXPECT_NEAR(r.at(500, 100, W, BoxRelation::kPassWindow).width_ratio, 0.75, 1e-12);
  // The edge wander is the relation's for every pass.
  EXPECT_EQ(r.at(8, 8, W, BoxRelation::kPassWindow).edge_noise_rel, 0.1);
  // Without a window grid, a window's box takes the main grid.
  const BoxRelation main_only = BoxRelation::parse(kTwoByTwo, "two.yaml");
  EXPECT_FALSE(main_only.has_window_grid());
  EXPECT_NEAR(main_only.at(20, 20, W, BoxRelation::kPassWindow).width_ratio, 0.7, 1e-12);
  // The sphere relation: ratio 1 for every pass.
  EXPECT_EQ(BoxRelation::sphere().at(8, 8, W, BoxRelation::kPassWindow).width_ratio, 1.0);
}

TEST(BoxRelation, WritesWhatItReadsBack) {
  const BoxRelation r = BoxRelation::parse(kTwoByTwo, "two.yaml");
  const BoxRelation back = BoxRelation::parse(r.to_yaml("a header"), "back.yaml");
  EXPECT_EQ(back.table().width_ratio, r.table().width_ratio);
  EXPECT_EQ(back.table().size_edges, r.table().size_edges);
  EXPECT_EQ(back.model_id(), r.model_id());
  EXPECT_FALSE(back.has_window_grid());
  const BoxRelation w = BoxRelation::parse(kWithWindow, "window.yaml");
  const BoxRelation w_back = BoxRelation::parse(w.to_yaml("a header"), "back.yaml");
  EXPECT_EQ(w_back.table().window.size_edges, w.table().window.size_edges);
  EXPECT_EQ(w_back.table().window.width_ratio, w.table().window.width_ratio);
  EXPECT_EQ(w_back.table().window.count, w.table().window.count);
}

std::string error_of(const std::string& text) {
  try {
    BoxRelation::parse(text, "bad.yaml");
  } catch (const BoxRelationError& e) {
    return e.what();
  }
  return "";
}

TEST(BoxRelation, ABadFileIsOneErrorNamingTheFileAndKey) {
  std::string t = kTwoByTwo;
  const auto with = [&](const std::string& from, const std::string& to) {
    std::string s = t;
    s.replace(s.find(from), from.size(), to);
    return s;
  };
  EXPECT_NE(error_of(with("[0.6, 0.7, 0.8, 0.9]", "[0.6, 0.7, 0.8]")).find("bad.yaml"), std::string::npos);
  EXPECT_NE(
      error_of(with("[0.6, 0.7, 0.8, 0.9]", "[0.6, 0.7, 0.8]")).find("box_relation.width_ratio: 3 values, expected 4"),
      std::string::npos);
  EXPECT_NE(error_of(with("[0.5, 0.55", "[0, 0.55")).find("box_relation.height_ratio"), std::string::npos);
  EXPECT_NE(error_of(with("[0.6, 0.7, 0.8, 0.9]", "[0.6, .nan, 0.8, 0.9]")).find("box_relation.width_ratio"),
            std::string::npos);
  EXPECT_NE(error_of(with("[0.01, 0.04, 0.16]", "[0.04, 0.01, 0.16]")).find("box_relation.size_edges"),
            std::string::npos);
  EXPECT_NE(error_of(with("sha256:0123456789abcdef", "0123")).find("box_relation.model_id"), std::string::npos);
  // The window grid: all or nothing, checked like the main one.
  t = kWithWindow;
  EXPECT_EQ(error_of(t), "");
  EXPECT_NE(error_of(with("    width_ratio: [1.0, 0.75]", "    width_ratio: [1.0]"))
                .find("box_relation.window.width_ratio: 1 values, expected 2"),
            std::string::npos);
  EXPECT_NE(error_of(with("    size_edges: [4, 16, 64]", "    size_edges: [16, 4, 64]"))
                .find("box_relation.window.size_edges"),
            std::string::npos);
  EXPECT_NE(error_of(with("    size_edges: [4, 16, 64]\n", "")).find("box_relation.window.size_edges"),
            std::string::npos);
  EXPECT_NE(error_of(with("    range_sigma_rel: [0.3, 0.1]", "    range_sigma_rel: [0.3, -0.1]"))
                .find("box_relation.window.range_sigma_rel"),
            std::string::npos);
  EXPECT_NE(error_of(with("    count: [12, 40]", "    cuont: [12, 40]")).find("box_relation.window.cuont"),
            std::string::npos);
  EXPECT_NE(error_of(with("  model: \"test\"", "  modle: \"test\"")).find("box_relation.modle"), std::string::npos);
  EXPECT_NE(error_of("target:\n  radius_m: 0.3\n").find("bad.yaml"), std::string::npos);
  EXPECT_NE(error_of("[1, 2").find("bad.yaml"), std::string::npos);
}

TEST(BoxRelation, AMissingFileOrUnknownBuiltInIsNamed) {
  try {
    BoxRelation::load("/nonexistent/x.boxes.yaml");
    ADD_FAILURE();
  } catch (const BoxRelationError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.boxes.yaml"), std::string::npos);
  }
  try {
    BoxRelation::load("builtin:nope");
    ADD_FAILURE();
  } catch (const BoxRelationError& e) {
    EXPECT_NE(std::string(e.what()).find("builtin:wingman-small"), std::string::npos);
  }
  for (const char* not_a_file : {"/dev/zero", "/tmp"}) {  // a device that never ends, a folder
    try {
      BoxRelation::load(not_a_file);
      ADD_FAILURE() << not_a_file;
    } catch (const BoxRelationError& e) {
      EXPECT_NE(std::string(e.what()).find(not_a_file), std::string::npos);
    }
  }
  SphereLocalizerOptions o;
  o.box_relation = "/nonexistent/x.boxes.yaml";
  const auto p = o.validate();
  ASSERT_EQ(p.size(), 1u);
  EXPECT_NE(p[0].find("target.box_relation"), std::string::npos);
}

TEST(BoxRelation, DetectionsOfAnotherModelAreRefusedNamingBothIds) {
  const BoxRelation r = BoxRelation::parse(kTwoByTwo, "two.yaml");
  EXPECT_EQ(r.check_model("sha256:0123456789abcdef"), "");
  EXPECT_EQ(r.check_model(""), "");  // a detector that does not say
  const std::string bad = r.check_model("sha256:ffffffffffffffff");
  EXPECT_NE(bad.find("detections_t.model_id = 'sha256:ffffffffffffffff'"), std::string::npos);
  EXPECT_NE(bad.find("sha256:0123456789abcdef"), std::string::npos);
  EXPECT_NE(bad.find("target.box_relation"), std::string::npos);
  EXPECT_EQ(BoxRelation::sphere().check_model("sha256:ffffffffffffffff"), "");
}

TEST(BoxRelation, TheShippedRelationIsMeasuredForTheShippedWeights) {
  const BoxRelation r = BoxRelation::load("builtin:wingman-small");
  EXPECT_FALSE(r.is_sphere());
  EXPECT_EQ(r.model_id(), detector::weights_model_id("builtin:wingman-small"))
      << "models/wingman-small.boxes.yaml was measured for other weights: run `wingman model box-relation` again";
  // Outline boxes are smaller than the bounding sphere's.
  for (double w : r.table().width_ratio) EXPECT_LT(w, 1.0);
  // The tracker-driven windows' boxes have their own grid (docs/localization.md, "Box relation").
  EXPECT_TRUE(r.has_window_grid());
}

TEST(BoxRelation, RatiosScaleTheExactRangeAndTheirSpreadEntersTheCovariance) {
  // A sphere box at 10 m; read as the box of a model whose boxes are 0.7 of the sphere's, the box stands for a
  // sphere box 1 / 0.7 as large: the target is 0.7 as far.
  const CameraModel cam = CameraModel::pinhole(1280, 720, 640, 640, 639.5, 359.5);
  const SphereImageBox s = project_sphere(cam, {0.5, -0.3, 10.0}, 0.348);
  ASSERT_TRUE(s.valid);
  SphereLocalizerOptions o;
  const LocalizeResult one = localize_box(s.pixel_box(), cam, o);
  BoxScale k;
  k.width_ratio = k.height_ratio = 0.7;
  const LocalizeResult seven = localize_box(s.pixel_box(), cam, o, k);
  ASSERT_TRUE(one.ok && seven.ok);
  EXPECT_NEAR(one.measurement.range, std::sqrt(0.25 + 0.09 + 100.0), 1e-6);
  EXPECT_NEAR(seven.measurement.range / one.measurement.range, 0.7, 1e-9);
  k.range_sigma_rel = 0.1;
  const LocalizeResult spread = localize_box(s.pixel_box(), cam, o, k);
  const Eigen::Vector3d u = spread.measurement.p_target_in_cam.normalized();
  const double var_along = u.dot(spread.measurement.cov_p_in_cam * u) - u.dot(seven.measurement.cov_p_in_cam * u);
  EXPECT_NEAR(std::sqrt(var_along), 0.1 * seven.measurement.range, 1e-6);
}

}  // namespace
}  // namespace wingman::localizer
