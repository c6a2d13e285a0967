// SPDX-License-Identifier: MIT
// Fuzz target: wingman-detector's image input. The payload is an image_t, delivered as detector/main.cpp does:
// message limits from input.max_image_width/height (here 640 x 480), decode, validate_message with those limits,
// then image_to_bgr (the conversion every frame goes through before the network; its error drops the frame).
#include "fuzz_support.hpp"

#include <wingman/detector/preprocess.hpp>

#include <cstdlib>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace wingman;
  const common::ImageLimits image_limits{640, 480};
  common::MessageLimits limits;
  limits.image = image_limits;
  fuzz::deliver<image_t>(
      data, size, limits, [&](const image_t& img) { return common::validate_message(img, image_limits); },
      [](const image_t& img) {
        std::string error;
        const cv::Mat bgr = detector::image_to_bgr(img, &error);
        if (error.empty() && (bgr.empty() || bgr.cols != img.width || bgr.rows != img.height)) {
          std::fprintf(stderr, "image_to_bgr: %dx%d image gave a %dx%d Mat without an error\n", img.width, img.height,
                       bgr.cols, bgr.rows);
          std::abort();
        }
      });
  return 0;
}
