// SPDX-License-Identifier: MIT
// image_t conversion, Algorithm 2 regions (subsquare, zoom crop), coordinate mapping and input packing.
#include <wingman/detector/preprocess.hpp>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

namespace wingman::detector {
namespace {

wingman::image_t make_image(int w, int h, int stride, int8_t format, std::vector<uint8_t> data) {
  wingman::image_t m{};
  m.width = w;
  m.height = h;
  m.stride = stride;
  m.pixel_format = format;
  m.size = static_cast<int32_t>(data.size());
  m.data = std::move(data);
  return m;
}

TEST(ImageToBgr, Gray8WithPaddedStride) {
  // 5 x 3, stride 8: padding bytes must be ignored.
  std::vector<uint8_t> d(8 * 3, 255);
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 5; ++x) d[y * 8 + x] = static_cast<uint8_t>(10 * y + x);
  std::string err;
  const cv::Mat bgr = image_to_bgr(make_image(5, 3, 8, wingman::image_t::GRAY8, d), &err);
  ASSERT_TRUE(err.empty()) << err;
  ASSERT_EQ(bgr.size(), cv::Size(5, 3));
  EXPECT_EQ(bgr.at<cv::Vec3b>(2, 4), cv::Vec3b(24, 24, 24));
}

TEST(ImageToBgr, Bgr8KeepsChannelOrder) {
  std::vector<uint8_t> d(3 * 3 * 2);
  d[0] = 1;
  d[1] = 2;
  d[2] = 3;
  std::string err;
  const cv::Mat bgr = image_to_bgr(make_image(3, 2, 9, wingman::image_t::BGR8, d), &err);
  ASSERT_TRUE(err.empty()) << err;
  EXPECT_EQ(bgr.at<cv::Vec3b>(0, 0), cv::Vec3b(1, 2, 3));
}

TEST(ImageToBgr, YuyvGrey) {
  // Y = 128, U = V = 128 everywhere: mid grey.
  std::string err;
  const cv::Mat bgr =
      image_to_bgr(make_image(6, 3, 12, wingman::image_t::YUYV, std::vector<uint8_t>(12 * 3, 128)), &err);
  ASSERT_TRUE(err.empty()) << err;
  ASSERT_EQ(bgr.size(), cv::Size(6, 3));
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(bgr.at<cv::Vec3b>(1, 5)[c], 128, 2);
}

TEST(ImageToBgr, MjpegDecodes) {
  cv::Mat src(7, 9, CV_8UC3, cv::Scalar(200, 100, 50));
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", src, jpeg));
  std::string err;
  const cv::Mat bgr = image_to_bgr(make_image(9, 7, 0, wingman::image_t::MJPEG, jpeg), &err);
  ASSERT_TRUE(err.empty()) << err;
  ASSERT_EQ(bgr.size(), cv::Size(9, 7));
  EXPECT_NEAR(bgr.at<cv::Vec3b>(3, 4)[0], 200, 6);
  // Wrong declared size.
  EXPECT_TRUE(image_to_bgr(make_image(10, 7, 0, wingman::image_t::MJPEG, jpeg), &err).empty());
  EXPECT_NE(err.find("image_t.width"), std::string::npos) << err;
}

TEST(ImageToBgr, MjpegWhoseHeaderClaimsAnotherSizeIsRejectedBeforeDecoding) {
  cv::Mat src(8, 16, CV_8UC3, cv::Scalar(200, 100, 50));
  std::vector<uint8_t> jpeg;
  ASSERT_TRUE(cv::imencode(".jpg", src, jpeg));
  size_t sof = 2;
  while (sof + 8 < jpeg.size() && !(jpeg[sof] == 0xFF && jpeg[sof + 1] == 0xC0)) ++sof;
  ASSERT_LT(sof + 8, jpeg.size());
  jpeg[sof + 5] = jpeg[sof + 7] = 30000 >> 8;  // 30000 x 30000: decoding would allocate 2.7 GB
  jpeg[sof + 6] = jpeg[sof + 8] = 30000 & 0xff;
  std::string err;
  EXPECT_TRUE(image_to_bgr(make_image(16, 8, 0, wingman::image_t::MJPEG, jpeg), &err).empty());
  EXPECT_NE(err.find("the JPEG header says 30000x30000"), std::string::npos) << err;
  EXPECT_TRUE(image_to_bgr(make_image(16, 8, 0, wingman::image_t::MJPEG, {1, 2, 3, 4}), &err).empty());
  EXPECT_NE(err.find("not a JPEG"), std::string::npos) << err;
}

TEST(ImageToBgr, ImpossibleMessagesNameTheField) {
  std::string err;
  EXPECT_TRUE(image_to_bgr(make_image(0, 3, 3, wingman::image_t::GRAY8, {}), &err).empty());
  EXPECT_NE(err.find("image_t.width = 0"), std::string::npos) << err;
  EXPECT_TRUE(image_to_bgr(make_image(5, 3, 4, wingman::image_t::GRAY8, std::vector<uint8_t>(15)), &err).empty());
  EXPECT_NE(err.find("image_t.stride = 4"), std::string::npos) << err;
  EXPECT_TRUE(image_to_bgr(make_image(5, 3, 5, wingman::image_t::GRAY8, std::vector<uint8_t>(14)), &err).empty());
  EXPECT_NE(err.find("image_t.size = 14"), std::string::npos) << err;
  EXPECT_TRUE(image_to_bgr(make_image(5, 3, 10, wingman::image_t::YUYV, std::vector<uint8_t>(30)), &err).empty());
  EXPECT_NE(err.find("even"), std::string::npos) << err;
  EXPECT_TRUE(image_to_bgr(make_image(5, 3, 5, 9, std::vector<uint8_t>(15)), &err).empty());
  EXPECT_NE(err.find("image_t.pixel_format = 9"), std::string::npos) << err;
}

TEST(Algorithm2Geometry, SubsquareIsCentredSquare) {
  EXPECT_EQ(detection_region({1280, 720}, true), cv::Rect(280, 0, 720, 720));
  EXPECT_EQ(detection_region({1280, 720}, false), cv::Rect(0, 0, 1280, 720));
  EXPECT_EQ(detection_region({641, 480}, true), cv::Rect(80, 0, 480, 480));  // odd: left edge rounds down
  EXPECT_EQ(detection_region({480, 640}, true), cv::Rect(0, 80, 480, 480));
}

TEST(Algorithm2Geometry, ZoomCropIsClampedInsideTheImage) {
  const cv::Size img(1280, 720), net(416, 416);
  EXPECT_EQ(zoom_crop(img, net, 640, 360), cv::Rect(432, 152, 416, 416));
  EXPECT_EQ(zoom_crop(img, net, 10, 5), cv::Rect(0, 0, 416, 416));            // top-left corner
  EXPECT_EQ(zoom_crop(img, net, 1279, 719), cv::Rect(864, 304, 416, 416));    // bottom-right corner
  EXPECT_EQ(zoom_crop({300, 200}, net, 150, 100), cv::Rect(0, 0, 300, 200));  // smaller than the network
}

TEST(Algorithm2Geometry, NetworkBoxMapsToFullImagePixels) {
  // Centre of the network input in the 720 x 720 subsquare of a 1280 x 720 image is the image centre.
  const Box in_net{208.0f, 104.0f, 41.6f, 20.8f, 0.5f, Pass::kSingle};
  const Box b = network_to_image(in_net, cv::Rect(280, 0, 720, 720), {416, 416});
  EXPECT_NEAR(b.cx, 280.0f + 360.0f, 1e-3);
  EXPECT_NEAR(b.cy, 180.0f, 1e-3);
  EXPECT_NEAR(b.w, 72.0f, 1e-3);
  EXPECT_NEAR(b.h, 36.0f, 1e-3);
  EXPECT_FLOAT_EQ(b.confidence, 0.5f);
}

TEST(NetworkInput, RgbPlanesScaledToUnit) {
  // 37 x 23 image: blue on the left part, red on the right; the ROI is the whole image stretched to 13 x 11.
  cv::Mat bgr(23, 37, CV_8UC3, cv::Scalar(255, 0, 0));
  bgr(cv::Rect(20, 0, 17, 23)).setTo(cv::Scalar(0, 0, 255));
  cv::Mat scratch;
  std::vector<float> chw(3 * 13 * 11, -1.0f);
  to_network_input(bgr, cv::Rect(0, 0, 37, 23), {13, 11}, scratch, chw.data());
  const int plane = 13 * 11;
  // Top-left pixel is blue: R plane 0, B plane 1.
  EXPECT_FLOAT_EQ(chw[0], 0.0f);
  EXPECT_FLOAT_EQ(chw[2 * plane], 1.0f);
  // Bottom-right pixel is red.
  EXPECT_FLOAT_EQ(chw[plane - 1], 1.0f);
  EXPECT_FLOAT_EQ(chw[3 * plane - 1], 0.0f);
}

}  // namespace
}  // namespace wingman::detector
