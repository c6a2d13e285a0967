// SPDX-License-Identifier: MIT
// The built-in models (builtin:wingman-small, builtin:tiny-yolo-thesis) against the files in models/, and the errors
// for names and paths that do not exist.
#include <wingman/detector/darknet_cfg.hpp>
#include <wingman/detector/darknet_weights.hpp>
#include <wingman/detector/detector_options.hpp>
#include <wingman/detector/model_loader.hpp>

#include "test_support.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>

namespace wingman::detector {
namespace {

std::string error_of(const std::string& cfg, const std::string& weights) {
  try {
    load_model(cfg, weights);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(no error)";
}

std::vector<char> read_file(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

TEST(BuiltinModels, CfgsAreTheFilesInModels) {
  std::ifstream small_file(testing::source_path("models/wingman-small.cfg"));
  EXPECT_EQ(std::string(builtin_small_cfg()),
            std::string(std::istreambuf_iterator<char>(small_file), std::istreambuf_iterator<char>()));
  std::ifstream thesis_file(testing::source_path("models/tiny-yolo-thesis.cfg"));
  EXPECT_EQ(std::string(builtin_thesis_cfg()),
            std::string(std::istreambuf_iterator<char>(thesis_file), std::istreambuf_iterator<char>()));
}

TEST(BuiltinModels, ShippedWeightsAreBuiltInByteForByte) {
  const std::string path = testing::source_path("models/wingman-small.weights");
  if (!std::filesystem::exists(path)) GTEST_SKIP() << path << " is absent: this build has no built-in weights";
  EXPECT_EQ(builtin_small_weights(), read_file(path));
  const DarknetModel m = load_model("builtin:wingman-small", "builtin:wingman-small");
  EXPECT_EQ(serialize_darknet_weights(m), read_file(path));
  // The process defaults are the shipped model.
  const DetectorOptions o;
  EXPECT_EQ(o.cfg, "builtin:wingman-small");
  EXPECT_EQ(o.weights, "builtin:wingman-small");
}

TEST(BuiltinModels, UnknownNamesEmptyCfgAndMissingFilesAreErrorsNamingThem) {
  EXPECT_NE(error_of("builtin:yolov9", "")
                .find("model.cfg = 'builtin:yolov9': no such built-in network; expected one "
                      "of builtin:wingman-small, builtin:tiny-yolo-thesis"),
            std::string::npos)
      << error_of("builtin:yolov9", "");
  EXPECT_NE(error_of("builtin:wingman-small", "builtin:thesis").find("model.weights = 'builtin:thesis'"),
            std::string::npos);
  EXPECT_NE(error_of("", "x.weights").find("model.cfg is empty"), std::string::npos);
  EXPECT_NE(error_of("/nonexistent/a.cfg", "b.weights").find("/nonexistent/a.cfg"), std::string::npos);
  // The thesis network does not take the shipped model's weights: the size mismatch is named.
  if (!builtin_small_weights().empty()) {
    EXPECT_NE(error_of("builtin:tiny-yolo-thesis", "builtin:wingman-small").find("<built-in wingman-small.weights>"),
              std::string::npos)
        << error_of("builtin:tiny-yolo-thesis", "builtin:wingman-small");
  }
  DetectorOptions o;
  o.cfg = "";
  ASSERT_EQ(o.validate().size(), 1u);
  EXPECT_NE(o.validate()[0].find("model.cfg"), std::string::npos);
}

}  // namespace
}  // namespace wingman::detector
