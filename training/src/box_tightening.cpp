// SPDX-License-Identifier: MIT
// Box tightening against a smooth background.
#include "wingman/training/box_tightening.hpp"

#include <fmt/format.h>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

namespace wingman::training {

std::vector<std::string> TightenOptions::validate() const {
  std::vector<std::string> p;
  auto range = [&](const char* name, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi)) p.push_back(fmt::format("tighten.{} = {}: must be in {}..{}", name, v, lo, hi));
  };
  range("border_fraction", border_fraction, 0.0, 0.4);
  if (!(outside_px >= 0)) p.push_back(fmt::format("tighten.outside_px = {}: must be >= 0", outside_px));
  if (!(k_sigma > 0)) p.push_back(fmt::format("tighten.k_sigma = {}: must be > 0", k_sigma));
  range("min_contrast", min_contrast, 0.0, 255.0);
  range("max_band_foreground", max_band_foreground, 0.0, 1.0);
  range("max_fill", max_fill, 0.0, 1.0);
  if (!(merge_fraction >= 0)) p.push_back(fmt::format("tighten.merge_fraction = {}: must be >= 0", merge_fraction));
  if (min_size_px < 1) p.push_back(fmt::format("tighten.min_size_px = {}: must be >= 1", min_size_px));
  return p;
}

namespace {

struct Plane {
  double a = 0, b = 0, c = 0;
  double at(double x, double y) const { return a + b * x + c * y; }
};

/// Least-squares plane through (x, y, v) samples selected by `use`.
bool fit_plane(const std::vector<cv::Point3d>& s, const std::vector<bool>& use, Plane& out) {
  cv::Matx33d A = cv::Matx33d::zeros();
  cv::Vec3d rhs(0, 0, 0);
  int n = 0;
  for (size_t i = 0; i < s.size(); ++i) {
    if (!use[i]) continue;
    const cv::Vec3d f(1.0, s[i].x, s[i].y);
    A += f * f.t();
    rhs += f * s[i].z;
    ++n;
  }
  if (n < 3) return false;
  cv::Vec3d sol;
  if (!cv::solve(A, rhs, sol, cv::DECOMP_SVD)) return false;
  out = {sol[0], sol[1], sol[2]};
  return true;
}

double median_of(std::vector<double> v) {
  if (v.empty()) return 0.0;
  const size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  return v[mid];
}

}  // namespace

TightenResult tighten_box(const cv::Mat& bgr, const cv::Rect2d& loose, const TightenOptions& o) {
  TightenResult r;
  r.box = loose;
  auto fail = [&](const std::string& why) {
    r.reason = why;
    return r;
  };
  if (bgr.empty() || bgr.type() != CV_8UC3) return fail("not an 8-bit BGR image");
  // The box's pixels: [x0, x1) x [y0, y1), clipped to the image.
  const int x0 = std::max(0, static_cast<int>(std::floor(loose.x)));
  const int y0 = std::max(0, static_cast<int>(std::floor(loose.y)));
  const int x1 = std::min(bgr.cols, static_cast<int>(std::ceil(loose.x + loose.width)));
  const int y1 = std::min(bgr.rows, static_cast<int>(std::ceil(loose.y + loose.height)));
  const int w = x1 - x0, h = y1 - y0;
  if (w < 6 || h < 6) return fail(fmt::format("box {}x{} px is too small to fit a background band", w, h));
  const int bw = std::max(1, static_cast<int>(std::lround(o.border_fraction * w)));
  const int bh = std::max(1, static_cast<int>(std::lround(o.border_fraction * h)));
  const int out_px = static_cast<int>(std::lround(o.outside_px));
  const cv::Rect outer =
      cv::Rect(x0 - out_px, y0 - out_px, w + 2 * out_px, h + 2 * out_px) & cv::Rect(0, 0, bgr.cols, bgr.rows);
  cv::Mat gray;
  cv::cvtColor(bgr(outer), gray, cv::COLOR_BGR2GRAY);

  // Background samples: the outer band of the box and the pixels outside it; the edge check uses the pixels
  // outside and the box's outermost 2 px.
  std::vector<cv::Point3d> band;
  std::vector<bool> at_edge;
  for (int y = outer.y; y < outer.y + outer.height; ++y)
    for (int x = outer.x; x < outer.x + outer.width; ++x) {
      const bool inside = x >= x0 && x < x1 && y >= y0 && y < y1;
      const bool core = x >= x0 + bw && x < x1 - bw && y >= y0 + bh && y < y1 - bh;
      if (core) continue;
      band.emplace_back(x, y, gray.at<uchar>(y - outer.y, x - outer.x));
      const bool edge = !inside || x < x0 + 2 || x >= x1 - 2 || y < y0 + 2 || y >= y1 - 2;
      at_edge.push_back(edge);
    }
  // Robust fit: start from the median level, then twice a least-squares plane on the inliers.
  std::vector<double> levels;
  for (const auto& s : band) levels.push_back(s.z);
  Plane plane{median_of(levels), 0, 0};
  double sigma = 0;
  std::vector<bool> inlier(band.size(), true);
  for (int pass = 0; pass < 3; ++pass) {
    std::vector<double> abs_res;
    for (const auto& s : band) abs_res.push_back(std::fabs(s.z - plane.at(s.x, s.y)));
    sigma = std::max(1.0, 1.4826 * median_of(abs_res));
    const double keep = std::max(3.0 * sigma, 0.5 * o.min_contrast);
    for (size_t i = 0; i < band.size(); ++i) inlier[i] = abs_res[i] <= keep;
    if (pass < 2 && !fit_plane(band, inlier, plane)) return fail("cannot fit the background");
  }
  const double thresh = std::max(o.k_sigma * sigma, o.min_contrast);
  size_t edge_n = 0, edge_fg = 0;
  for (size_t i = 0; i < band.size(); ++i) {
    if (!at_edge[i]) continue;
    ++edge_n;
    if (std::fabs(band[i].z - plane.at(band[i].x, band[i].y)) > thresh) ++edge_fg;
  }
  if (edge_n == 0 || static_cast<double>(edge_fg) > o.max_band_foreground * static_cast<double>(edge_n))
    return fail(fmt::format("the box edge is not background-like ({} of {} edge pixels differ)", edge_fg, edge_n));

  cv::Mat mask(h, w, CV_8U, cv::Scalar(0));
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x)
      if (std::fabs(gray.at<uchar>(y - outer.y, x - outer.x) - plane.at(x, y)) > thresh)
        mask.at<uchar>(y - y0, x - x0) = 255;
  cv::morphologyEx(mask, mask, cv::MORPH_CLOSE, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(3, 3)));
  cv::Mat labels, stats, centroids;
  const int n = cv::connectedComponentsWithStats(mask, labels, stats, centroids, 8, CV_32S);
  int main_label = -1, main_area = 0;
  for (int i = 1; i < n; ++i) {
    const double cx = centroids.at<double>(i, 0), cy = centroids.at<double>(i, 1);
    if (cx < 0.25 * w || cx > 0.75 * w || cy < 0.25 * h || cy > 0.75 * h) continue;
    const int area = stats.at<int>(i, cv::CC_STAT_AREA);
    if (area > main_area) main_area = area, main_label = i;
  }
  if (main_label < 0) return fail("no object found in the middle of the box");
  auto rect_of = [&](int i) {
    return cv::Rect(stats.at<int>(i, cv::CC_STAT_LEFT), stats.at<int>(i, cv::CC_STAT_TOP),
                    stats.at<int>(i, cv::CC_STAT_WIDTH), stats.at<int>(i, cv::CC_STAT_HEIGHT));
  };
  cv::Rect tight = rect_of(main_label);
  const double reach = o.merge_fraction * std::max(w, h);
  for (int i = 1; i < n; ++i) {
    if (i == main_label) continue;
    const cv::Rect b = rect_of(i);
    const double dx = std::max({0, tight.x - (b.x + b.width), b.x - (tight.x + tight.width)});
    const double dy = std::max({0, tight.y - (b.y + b.height), b.y - (tight.y + tight.height)});
    if (std::hypot(dx, dy) <= reach) tight |= b;
  }
  const int sides = (tight.x == 0) + (tight.y == 0) + (tight.x + tight.width == w) + (tight.y + tight.height == h);
  if (sides >= 2) return fail(fmt::format("the object touches {} sides of the box", sides));
  if (static_cast<double>(tight.area()) > o.max_fill * w * h)
    return fail(fmt::format("the object fills {:.0f}% of the box (already tight)", 100.0 * tight.area() / (w * h)));
  if (tight.width < o.min_size_px || tight.height < o.min_size_px)
    return fail(fmt::format("the object is only {}x{} px", tight.width, tight.height));
  r.tightened = true;
  r.box = cv::Rect2d(x0 + tight.x, y0 + tight.y, tight.width, tight.height);
  return r;
}

}  // namespace wingman::training
