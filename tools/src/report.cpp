// SPDX-License-Identifier: MIT
// `wingman report`: one self-contained HTML page about a flight: inline SVG charts and camera frames as data URIs.
#include "wingman/tools/report.hpp"

#include "lcm_fingerprint.hpp"
#include "log_progress.hpp"

#include <wingman/common/lcm_log_reader.hpp>
#include <wingman/detector/preprocess.hpp>
#include <wingman/image_t.hpp>

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <stdexcept>

namespace wingman::tools {
namespace {

std::string escape_html(const std::string& s) {
  std::string o;
  for (char c : s) {
    switch (c) {
      case '<':
        o += "&lt;";
        break;
      case '>':
        o += "&gt;";
        break;
      case '&':
        o += "&amp;";
        break;
      case '"':
        o += "&quot;";
        break;
      default:
        o += c;
    }
  }
  return o;
}

std::string base64(const std::vector<uint8_t>& in) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const uint32_t v = (uint32_t{in[i]} << 16) | (uint32_t{in[i + 1]} << 8) | in[i + 2];
    for (int k = 18; k >= 0; k -= 6) out += kAlphabet[(v >> k) & 63];
  }
  if (i + 1 == in.size()) {
    const uint32_t v = uint32_t{in[i]} << 16;
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += "==";
  } else if (i + 2 == in.size()) {
    const uint32_t v = (uint32_t{in[i]} << 16) | (uint32_t{in[i + 1]} << 8);
    out += kAlphabet[(v >> 18) & 63];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += '=';
  }
  return out;
}

/// A chart area mapping data coordinates to SVG pixels.
struct Frame {
  double x0, x1, y0, y1;  // data range
  double w, h, pad;       // pixels
  double sx(double x) const { return pad + (x - x0) / (x1 - x0) * (w - 2 * pad); }
  double sy(double y) const { return h - pad - (y - y0) / (y1 - y0) * (h - 2 * pad); }
};

std::string svg_open(const char* id, const Frame& f) {
  return fmt::format(R"(<svg id="{}" xmlns="http://www.w3.org/2000/svg" width="{}" height="{}">)", id, f.w, f.h);
}

std::string polyline(const Frame& f, const std::vector<std::pair<double, double>>& pts, const char* colour,
                     double width) {
  if (pts.empty()) return "";
  std::string s =
      fmt::format(R"(<polyline class="data" fill="none" stroke="{}" stroke-width="{}" points=")", colour, width);
  for (const auto& [x, y] : pts) s += fmt::format("{:.1f},{:.1f} ", f.sx(x), f.sy(y));
  return s + "\"/>\n";
}

/// Frame, tick labels and axis titles; x ticks only when `x_ticks`.
std::string axes(const Frame& f, const std::string& xlabel, const std::string& ylabel, bool x_ticks = true) {
  std::string s = fmt::format(R"(<rect x="{}" y="{}" width="{}" height="{}" fill="#fbfbfb" stroke="#999"/>)", f.pad,
                              f.pad, f.w - 2 * f.pad, f.h - 2 * f.pad);
  for (int i = 0; i <= 4; ++i) {
    const double x = f.x0 + (f.x1 - f.x0) * i / 4.0, y = f.y0 + (f.y1 - f.y0) * i / 4.0;
    if (x_ticks) {
      s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="middle">{:.3g}</text>)", f.sx(x),
                       f.h - f.pad + 14, x);
    }
    s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="end">{:.3g}</text>)", f.pad - 4,
                     f.sy(y) + 4, y);
  }
  s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="12" text-anchor="middle">{}</text>)", f.w / 2, f.h - 4,
                   xlabel);
  s += fmt::format(R"svg(<text x="12" y="{:.1f}" font-size="12" transform="rotate(-90 12 {:.1f})" )svg"
                   R"(text-anchor="middle">{}</text>)",
                   f.h / 2, f.h / 2, ylabel);
  return s + "\n";
}

std::string no_data(const Frame& f, const std::string& what) {
  return fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="14" text-anchor="middle" fill="#777">{}</text>)",
                     f.w / 2, f.h / 2, escape_html(what));
}

std::string key(const char* colour, const char* label) {
  return fmt::format(R"(<span class="k" style="background:{}"></span>{})", colour, label);
}

std::string topdown_chart(const EvalResult& r) {
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (const auto* v : {&r.leader_truth, &r.leader_estimate, &r.follower_truth}) {
    for (const auto& s : *v) {
      x0 = std::min(x0, s.p.x());
      x1 = std::max(x1, s.p.x());
      y0 = std::min(y0, s.p.y());
      y1 = std::max(y1, s.p.y());
    }
  }
  if (x0 > x1) x0 = -1, x1 = 1, y0 = -1, y1 = 1;
  const double span = std::max({x1 - x0, y1 - y0, 2.0}) * 1.1;  // equal axis scales
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
  const Frame f{cx - span / 2, cx + span / 2, cy - span / 2, cy + span / 2, 560, 560, 48};
  const auto xy = [](const std::vector<EvalResult::Sample>& v) {
    std::vector<std::pair<double, double>> o;
    for (const auto& s : v) o.emplace_back(s.p.x(), s.p.y());
    return o;
  };
  std::string s = svg_open("topdown", f) + axes(f, "x (east), m", "y (north), m");
  s += polyline(f, xy(r.leader_truth), "#1f77b4", 2.0);
  s += polyline(f, xy(r.follower_truth), "#2ca02c", 2.0);
  for (const auto& e : r.leader_estimate) {
    s += fmt::format(R"(<circle class="data" cx="{:.1f}" cy="{:.1f}" r="1.6" fill="#d62728" fill-opacity="0.5"/>)",
                     f.sx(e.p.x()), f.sy(e.p.y()));
  }
  if (r.leader_truth.empty() && r.follower_truth.empty() && r.leader_estimate.empty()) s += no_data(f, "no paths");
  return s + "</svg>";
}

std::string errors_chart(const EvalResult& r) {
  double emax = 0.5;
  for (const auto& [t, e] : r.localization_error_over_time) emax = std::max(emax, e);
  for (const auto& [t, e] : r.formation_error_over_time) emax = std::max(emax, e);
  const Frame f{0.0, std::max(r.duration_s, 1.0), 0.0, emax * 1.1, 720, 300, 48};
  std::string s = svg_open("errors", f) + axes(f, "time, s", "error, m");
  s += polyline(f, r.localization_error_over_time, "#d62728", 1.2);
  s += polyline(f, r.formation_error_over_time, "#2ca02c", 1.5);
  if (r.localization_error_over_time.empty() && r.formation_error_over_time.empty())
    s += no_data(f, "no matched leader estimates");
  return s + "</svg>";
}

std::string bin_label(const RangeBin& b) {
  return std::isinf(b.hi_m) ? fmt::format("{:g}+ m", b.lo_m) : fmt::format("{:g}-{:g} m", b.lo_m, b.hi_m);
}

std::string range_chart(const EvalResult& r) {
  const auto& bins = r.localization_by_range;
  double ymax = 0.1;
  for (const auto& b : bins) ymax = std::max(ymax, b.error.rms);
  const Frame f{0.0, static_cast<double>(std::max<size_t>(bins.size(), 1)), 0.0, ymax * 1.2, 720, 300, 48};
  std::string s = svg_open("error-by-range", f) + axes(f, "true range", "RMS error, m", false);
  bool any = false;
  for (size_t i = 0; i < bins.size(); ++i) {
    const auto& b = bins[i];
    const double xc = f.sx(static_cast<double>(i) + 0.5), bw = 0.6 * (f.sx(1.0) - f.sx(0.0));
    s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="middle">{}</text>)", xc,
                     f.h - f.pad + 14, bin_label(b));
    if (b.error.n == 0) continue;
    any = true;
    s += fmt::format(R"(<rect class="data" x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="#9467bd">)"
                     R"(<title>{}: RMS {:.3f} m, mean {:.3f} m, n = {}</title></rect>)",
                     xc - bw / 2, f.sy(b.error.rms), bw, f.sy(0.0) - f.sy(b.error.rms), bin_label(b), b.error.rms,
                     b.error.mean, b.error.n);
    s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="middle">{:.2f} m (n={})</text>)", xc,
                     f.sy(b.error.rms) - 4, b.error.rms, b.error.n);
  }
  if (!any) s += no_data(f, "no matched estimates");
  return s + "</svg>";
}

std::string box_width_chart(const EvalResult& r) {
  double xmax = 1.0, ymax = 0.5;
  for (const auto& b : r.box_widths) {
    xmax = std::max(xmax, b.range_m);
    ymax = std::max({ymax, 100.0 * b.w_det_frac, 100.0 * b.w_truth_frac});
  }
  const Frame f{0.0, xmax * 1.05, 0.0, ymax * 1.1, 720, 340, 48};
  std::string s = svg_open("box-width", f) + axes(f, "truth range, m", "box width, % of image width");
  // At most ~1500 points per series, every k-th (deterministic).
  const size_t stride = std::max<size_t>(1, r.box_widths.size() / 1500);
  std::set<double> truth_drawn;
  for (size_t i = 0; i < r.box_widths.size(); i += stride) {
    const auto& b = r.box_widths[i];
    s += fmt::format(R"(<circle class="data" cx="{:.1f}" cy="{:.1f}" r="2" fill="#7f7f7f" fill-opacity="0.6"/>)",
                     f.sx(b.range_m), f.sy(100.0 * b.w_truth_frac));
    s += fmt::format(R"(<circle class="data" cx="{:.1f}" cy="{:.1f}" r="2.2" fill="{}" fill-opacity="0.7"/>)",
                     f.sx(b.range_m), f.sy(100.0 * b.w_det_frac), b.zoom_refined ? "#ff7f0e" : "#1f77b4");
  }
  if (r.box_widths.empty()) s += no_data(f, "no detections matched to the leader's truth box");
  return s + "</svg>";
}

std::string latency_chart(const EvalResult& r) {
  const auto& v = r.latency_samples_ms;
  constexpr int kBins = 24;
  double lo = 0.0, hi = 1.0;
  if (!v.empty()) {
    lo = std::min(0.0, *std::min_element(v.begin(), v.end()));
    hi = std::max(lo + 1e-3, *std::max_element(v.begin(), v.end())) * 1.0001;
  }
  std::vector<int64_t> count(kBins, 0);
  for (const double x : v) {
    const int i = std::clamp(static_cast<int>((x - lo) / (hi - lo) * kBins), 0, kBins - 1);
    ++count[static_cast<size_t>(i)];
  }
  const int64_t cmax = std::max<int64_t>(1, *std::max_element(count.begin(), count.end()));
  const Frame f{lo, hi, 0.0, static_cast<double>(cmax) * 1.1, 720, 300, 48};
  std::string s = svg_open("latency", f) + axes(f, "exposure to published target, ms", "targets_t messages");
  for (int i = 0; i < kBins; ++i) {
    if (count[static_cast<size_t>(i)] == 0) continue;
    const double a = lo + (hi - lo) * i / kBins, b = lo + (hi - lo) * (i + 1) / kBins;
    const double c = static_cast<double>(count[static_cast<size_t>(i)]);
    s += fmt::format(R"(<rect class="data" x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="#8c564b">)"
                     R"(<title>{:.2f}-{:.2f} ms: {}</title></rect>)",
                     f.sx(a) + 0.5, f.sy(c), std::max(0.5, f.sx(b) - f.sx(a) - 1.0), f.sy(0.0) - f.sy(c), a, b,
                     count[static_cast<size_t>(i)]);
  }
  if (v.empty()) s += no_data(f, "no latency samples (no targets with a matching exposure)");
  return s + "</svg>";
}

}  // namespace

std::vector<ReportFrame> draw_report_frames(const EvalResult& r, const EvalOptions& o) {
  std::vector<ReportFrame> out;
  const size_t n = r.image_utimes.size();
  if (n == 0 || o.report_frames <= 0) return out;
  std::set<size_t> wanted;  // indices among the image events, spread evenly
  const size_t k = std::min(n, static_cast<size_t>(o.report_frames));
  for (size_t i = 0; i < k; ++i) wanted.insert(k == 1 ? n / 2 : (i * (n - 1) + (k - 1) / 2) / (k - 1));
  common::LcmLogReader file(o.log);  // a corrupt event throws, naming its byte offset
  LogProgress progress(o.progress, o.log, file.file_ptr(), "drawing frames:");
  size_t index = 0;
  while (const common::LcmLogEvent* ev = file.read_next()) {
    progress.tick();
    if (ev->channel != o.image_channel ||
        lcm_fingerprint(ev->data, ev->datalen) != static_cast<uint64_t>(wingman::image_t::getHash()))
      continue;
    const size_t i = index++;
    if (!wanted.count(i)) continue;
    wingman::image_t img;
    if (img.decode(ev->data, 0, ev->datalen) < 0) continue;
    cv::Mat bgr = detector::image_to_bgr(img, nullptr);
    if (bgr.empty()) continue;
    const int thick = std::max(2, bgr.cols / 320);
    const auto rect = [](const EvalResult::FrameInfo::Box& b) {
      return cv::Rect(
          cv::Point(static_cast<int>(std::lround(b.cx - b.w / 2)), static_cast<int>(std::lround(b.cy - b.h / 2))),
          cv::Point(static_cast<int>(std::lround(b.cx + b.w / 2)), static_cast<int>(std::lround(b.cy + b.h / 2))));
    };
    const auto fi = r.frames.find(img.utime);
    if (fi != r.frames.end()) {
      for (const auto& b : fi->second.truth_boxes) {
        if (b.camera_id != img.camera_id || !b.flag) continue;
        const bool leader = b.vehicle_id == o.leader_id;
        cv::rectangle(bgr, rect(b), leader ? cv::Scalar(0, 200, 0) : cv::Scalar(160, 160, 160), thick);
        if (leader && fi->second.leader_track_id >= 0) {
          cv::putText(bgr, fmt::format("track {}", fi->second.leader_track_id),
                      cv::Point(rect(b).x, std::max(12 * thick, rect(b).y - 4 * thick)), cv::FONT_HERSHEY_SIMPLEX,
                      0.4 * thick, cv::Scalar(0, 200, 0), std::max(1, thick / 2), cv::LINE_AA);
        }
      }
      for (const auto& b : fi->second.detections) {
        if (b.camera_id != img.camera_id) continue;
        cv::rectangle(bgr, rect(b), b.flag ? cv::Scalar(14, 127, 255) : cv::Scalar(40, 39, 214), thick);
      }
    }
    if (bgr.cols > 640) {
      cv::resize(bgr, bgr, cv::Size(640, std::max(1, bgr.rows * 640 / bgr.cols)), 0, 0, cv::INTER_AREA);
    }
    std::vector<uint8_t> jpeg;
    if (!cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 85})) continue;
    out.push_back(
        {static_cast<double>(img.utime - r.first_truth_utime) * 1e-6, img.utime, base64(jpeg), bgr.cols, bgr.rows});
    if (i >= *wanted.rbegin()) break;
  }
  return out;
}

std::string html_report(const EvalResult& r, const EvalOptions& o, const std::vector<ReportFrame>& frames) {
  std::string html = "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" + escape_html(o.title) +
                     "</title>\n<style>body{font-family:sans-serif;margin:24px;color:#222} pre{background:#f4f4f4;"
                     "padding:12px} .k{display:inline-block;width:14px;height:4px;margin:0 6px 3px 12px}"
                     " figure{display:inline-block;margin:6px;vertical-align:top} figcaption{font-size:12px}"
                     " img.frame{max-width:380px;height:auto}</style>"
                     "</head><body>\n";
  html += "<h1>" + escape_html(o.title) + "</h1>\n";
  if (r.detection_source == "ground_truth") {
    html +=
        "<p><b>Detections came from simulator ground truth</b> (no trained detector model was used): these "
        "numbers measure localization, tracking and control, not detection.</p>\n";
  }
  html += "<p>Log: <code>" + escape_html(o.log) + "</code></p>\n<pre>" + escape_html(r.report()) + "</pre>\n";
  html += "<h2>Top-down view</h2><p>" + key("#1f77b4", "leader truth") + key("#d62728", "leader estimate") +
          key("#2ca02c", "follower") + "</p>\n" + topdown_chart(r) + "\n";
  html += "<h2>Errors over time</h2><p>" + key("#d62728", "localization |e| (leader)") +
          key("#2ca02c", "formation, horizontal") + "</p>\n" + errors_chart(r) + "\n";
  html +=
      "<h2>Localization error by range</h2><p>RMS of |estimate - truth| by the true follower-to-target "
      "distance.</p>\n" +
      range_chart(r) + "\n";
  html += "<h2>Box width over distance</h2><p>" + key("#7f7f7f", "truth (projected)") +
          key("#1f77b4", "detection, single pass") + key("#ff7f0e", "detection, zoom-in") + "</p>\n" +
          box_width_chart(r) + "\n";
  html +=
      "<h2>Latency</h2><p>From the exposure (the earlier log-event time of the image and the ground truth of the "
      "target's source_utime) to the published targets_t, wall clock as recorded by the logger.</p>\n" +
      latency_chart(r) + "\n";
  html += "<h2>Camera frames</h2>\n";
  if (r.image_utimes.empty()) {
    html += "<p id=\"no-images\">This log has no camera images on " + escape_html(o.image_channel) +
            " (record them with <code>tools/fly.sh --record-images</code>).</p>\n";
  } else {
    html += "<p>" + key("#00c800", "truth box (leader, with its matched track id)") +
            key("#a0a0a0", "truth box (other)") + key("#d62728", "detection, single pass") +
            key("#ff7f0e", "detection, zoom-in") + "</p>\n<div id=\"frames\">\n";
    for (const auto& f : frames) {
      html += fmt::format(
          "<figure><img class=\"frame\" width=\"{}\" height=\"{}\" alt=\"frame at {:.2f} s\" "
          "onload=\"this.setAttribute('data-decoded','1')\" src=\"data:image/jpeg;base64,{}\">"
          "<figcaption>t = {:.2f} s (utime {})</figcaption></figure>\n",
          f.width, f.height, f.t_s, f.jpeg_b64, f.t_s, f.utime);
    }
    if (frames.empty()) html += "<p>None of the images could be decoded.</p>\n";
    html += "</div>\n";
  }
  return html + "</body></html>\n";
}

void write_html_report(const EvalResult& r, const EvalOptions& o, const std::string& path) {
  const std::string html = html_report(r, o, draw_report_frames(r, o));
  std::ofstream f(path);
  f << html;
  if (!f) throw std::runtime_error("wingman report: cannot write '" + path + "'");
}

}  // namespace wingman::tools
