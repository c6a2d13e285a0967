// SPDX-License-Identifier: MIT
// wingman-test-blob-stage: a pipeline stage for testing the runtime and the replay player. It reads
// image_t (GRAY8/BGR8), finds the bounding box of the pixels brighter than a threshold, and publishes
// it as detections_t — a deterministic function of the image, like the real detector will be.
#include <wingman/common/runtime.hpp>

#include <opencv2/imgproc.hpp>

namespace {

struct BlobStageOptions {
  std::string input_channel = "IMAGE_CAM0";
  std::string output_channel = "DETECTIONS_CAM0";
  int threshold = 200;       ///< grey level above which a pixel belongs to the blob, 0..255
  int64_t hang_on_seq = -1;  ///< tests of the watchdog: the handler of the image with this seq never returns; -1 never

  template <class V>
  void visit(V& v) {
    v("input.channel", input_channel, "image_t input channel");
    v("output.channel", output_channel, "detections_t output channel");
    v("blob.threshold", threshold, "grey level above which a pixel is part of the blob, 0..255");
    v("test.hang_on_seq", hang_on_seq, "the handler of this image seq never returns (watchdog tests); -1 never");
  }
  std::vector<std::string> validate() const {
    std::vector<std::string> p;
    if (threshold < 0 || threshold > 255)
      p.push_back(wingman::common::problem("blob.threshold", threshold, "must be in 0..255"));
    return p;
  }
};

}  // namespace

int main(int argc, char** argv) {
  using namespace wingman;
  const common::ProcessInfo info{"blob_stage", "wingman-test-blob-stage", "Test stage: brightest blob as a detection"};
  return common::run_process<BlobStageOptions>(info, argc, argv, [](common::Runtime& rt, const BlobStageOptions& o) {
    rt.status().declare_output(o.output_channel);
    rt.subscribe<image_t>(o.input_channel, [&](const image_t& img) {
      if (img.seq == o.hang_on_seq) {
        // A livelock for the watchdog tests: busy for ever (the watchdog or the test's time bound ends it).
        volatile uint64_t spins = 0;
        for (;;) spins = spins + 1;
      }
      if (img.pixel_format != image_t::GRAY8 && img.pixel_format != image_t::BGR8) {
        throw std::runtime_error("image_t.pixel_format = " + common::pixel_format_name(img.pixel_format) +
                                 ": blob stage takes GRAY8 or BGR8");
      }
      const int type = img.pixel_format == image_t::GRAY8 ? CV_8UC1 : CV_8UC3;
      const cv::Mat view(img.height, img.width, type, const_cast<uint8_t*>(img.data.data()),
                         static_cast<size_t>(img.stride));
      cv::Mat gray;
      if (type == CV_8UC3)
        cv::cvtColor(view, gray, cv::COLOR_BGR2GRAY);
      else
        gray = view;
      cv::Mat mask;
      cv::threshold(gray, mask, o.threshold, 255, cv::THRESH_BINARY);
      detections_t out{};
      out.utime = img.utime;
      out.seq = img.seq;
      out.camera_id = img.camera_id;
      out.image_width = img.width;
      out.image_height = img.height;
      if (cv::countNonZero(mask) > 0) {
        const cv::Rect r = cv::boundingRect(mask);
        detection_t d{};
        d.cx = static_cast<float>(r.x + 0.5 * r.width);
        d.cy = static_cast<float>(r.y + 0.5 * r.height);
        d.w = static_cast<float>(r.width);
        d.h = static_cast<float>(r.height);
        d.confidence = 1.0f;
        d.drone_score = 1.0f;  // a drone (class 0): the same as confidence
        out.detections.push_back(d);
      }
      out.num_detections = static_cast<int32_t>(out.detections.size());
      rt.publish(o.output_channel, out);
      rt.status().set_last_processed_seq(img.seq);
    });
    return rt.spin();
  });
}
