// SPDX-License-Identifier: MIT
// `wingman report`: one self-contained HTML page about a flight: inline SVG charts and camera frames as data URIs.
#include "wingman/tools/report.hpp"

#include "lcm_fingerprint.hpp"
#include "log_progress.hpp"

#include <wingman/common/lcm_log_reader.hpp>
#include <wingman/detector/preprocess.hpp>
#include <wingman/image_t.hpp>

#include <fmt/format.h>
#include <openssl/evp.h>
#include <lcm/lcm-cpp.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
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
  // OpenSSL's encoder (RFC 4648, with padding); the report's thumbnails are a few kB, far below its int limit.
  if (in.size() > static_cast<size_t>(std::numeric_limits<int>::max() / 4 * 3))
    throw std::length_error("base64: " + std::to_string(in.size()) + " bytes: too large to embed");
  std::string out(4 * ((in.size() + 2) / 3) + 1, '\0');  // EVP_EncodeBlock writes a terminating NUL
  const int n = EVP_EncodeBlock(reinterpret_cast<unsigned char*>(out.data()), in.data(), static_cast<int>(in.size()));
  out.resize(static_cast<size_t>(n));
  return out;
}

/// Estimated width of a tick label at font-size 11 (sans-serif digits are about 0.55 em), pixels.
double label_width_px(const std::string& s) { return 6.5 * static_cast<double>(s.size()); }

/// A chart area mapping data coordinates to SVG pixels; the plot area is inset by the margins.
struct Frame {
  double x0, x1, y0, y1;            // data range
  double w, h;                      // pixels
  double left, right, top, bottom;  // margins, pixels
  double sx(double x) const { return left + (x - x0) / (x1 - x0) * (w - left - right); }
  double sy(double y) const { return h - bottom - (y - y0) / (y1 - y0) * (h - top - bottom); }
};

/// A chart's frame from its ticks: the left margin fits the widest y label beside the rotated y title, the right
/// one half of the last x label. x ticks may be empty (a categorical x axis from 0 to n_categories).
struct Chart {
  Frame f;
  AxisTicks xt, yt;
  bool x_ticks = true;
};

Chart make_chart(const AxisTicks& xt, const AxisTicks& yt, double w, double h, bool x_ticks = true) {
  double widest = 0.0;
  for (const double y : yt.values) widest = std::max(widest, label_width_px(tick_label(y, yt.step)));
  const double left = 30.0 + widest;  // 20 px for the rotated title, 6 px gap, labels, 4 px to the axis
  double right = 16.0;
  if (x_ticks && !xt.values.empty()) right = std::max(right, label_width_px(tick_label(xt.hi, xt.step)) / 2 + 4);
  return {Frame{xt.lo, xt.hi, yt.lo, yt.hi, w, h, left, right, 12.0, 44.0}, xt, yt, x_ticks};
}

std::string svg_open(const char* id, const Frame& f) {
  return fmt::format(R"(<svg id="{}" xmlns="http://www.w3.org/2000/svg" width="{:.0f}" height="{:.0f}">)", id, f.w,
                     f.h);
}

std::string polyline(const Frame& f, const std::vector<std::pair<double, double>>& pts, const char* colour,
                     double width) {
  if (pts.empty()) return "";
  std::string s =
      fmt::format(R"(<polyline class="data" fill="none" stroke="{}" stroke-width="{}" points=")", colour, width);
  for (const auto& [x, y] : pts) s += fmt::format("{:.1f},{:.1f} ", f.sx(x), f.sy(y));
  return s + "\"/>\n";
}

/// Plot area, grid lines and labels at the ticks, and the axis titles (with their units).
std::string axes(const Chart& c, const std::string& xlabel, const std::string& ylabel) {
  const Frame& f = c.f;
  const double px0 = f.left, px1 = f.w - f.right, py0 = f.top, py1 = f.h - f.bottom;
  std::string s = fmt::format(R"(<rect x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="#fbfbfb"/>)", px0,
                              py0, px1 - px0, py1 - py0);
  for (const double y : c.yt.values) {
    const double py = f.sy(y);
    s += fmt::format(R"(<line x1="{:.1f}" y1="{:.1f}" x2="{:.1f}" y2="{:.1f}" stroke="#e3e3e3"/>)", px0, py, px1, py);
    s += fmt::format(R"(<text class="ytick" x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="end">{}</text>)", px0 - 4,
                     py + 4, tick_label(y, c.yt.step));
  }
  if (c.x_ticks) {
    for (const double x : c.xt.values) {
      const double px = f.sx(x);
      s += fmt::format(R"(<line x1="{:.1f}" y1="{:.1f}" x2="{:.1f}" y2="{:.1f}" stroke="#e3e3e3"/>)", px, py0, px, py1);
      s += fmt::format(R"(<text class="xtick" x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="middle">{}</text>)", px,
                       py1 + 15, tick_label(x, c.xt.step));
    }
  }
  s += fmt::format(R"(<rect x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="none" stroke="#999"/>)", px0,
                   py0, px1 - px0, py1 - py0);
  s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="12" text-anchor="middle">{}</text>)", 0.5 * (px0 + px1),
                   f.h - 6, escape_html(xlabel));
  const double yc = 0.5 * (py0 + py1);
  s += fmt::format(R"svg(<text x="14" y="{:.1f}" font-size="12" transform="rotate(-90 14 {:.1f})" )svg"
                   R"(text-anchor="middle">{}</text>)",
                   yc, yc, escape_html(ylabel));
  return s + "\n";
}

std::string no_data(const Frame& f, const std::string& what) {
  return fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="14" text-anchor="middle" fill="#777">{}</text>)",
                     0.5 * (f.left + f.w - f.right), 0.5 * (f.top + f.h - f.bottom), escape_html(what));
}

std::string key(const char* colour, const char* label) {
  return fmt::format(R"(<span class="k" style="background:{}"></span>{})", colour, label);
}

/// The leading digit of a 1-2-5 step: 1, 2 or 5.
double mantissa(double step) {
  const double m = step / std::pow(10.0, std::floor(std::log10(step) + 1e-9));
  return std::round(m);
}

/// Ticks of `step` from the multiple of it at or below lo to the one at or above hi, then `extra` more intervals
/// (half below, the rest above).
AxisTicks ticks_with_step(double lo, double hi, double step, int64_t extra = 0) {
  AxisTicks t;
  t.step = step;
  int64_t a = static_cast<int64_t>(std::floor(lo / step + 1e-9)), b = static_cast<int64_t>(std::ceil(hi / step - 1e-9));
  if (b <= a) b = a + 1;
  a -= extra / 2;
  b += extra - extra / 2;
  for (int64_t i = a; i <= b; ++i) t.values.push_back(static_cast<double>(i) * step);
  t.lo = t.values.front();
  t.hi = t.values.back();
  return t;
}

int64_t intervals(double lo, double hi, double step) {
  const auto a = static_cast<int64_t>(std::floor(lo / step + 1e-9)),
             b = static_cast<int64_t>(std::ceil(hi / step - 1e-9));
  return std::max<int64_t>(1, b - a);
}

/// The smallest 1-2-5 step >= min_step giving at most max_intervals intervals over every [lo, hi] of `ranges`.
double nice_step(const std::vector<std::pair<double, double>>& ranges, int max_intervals, double min_step) {
  double span = 0.0;
  for (const auto& [lo, hi] : ranges) span = std::max(span, hi - lo);
  max_intervals = std::max(1, max_intervals);
  if (!(span > 0.0)) span = 1.0;
  double step = std::pow(10.0, std::floor(std::log10(span / max_intervals)));
  for (int guard = 0; guard < 64; ++guard) {
    for (const double m : {1.0, 2.0, 5.0}) {
      const double s = m * step;
      if (s + 1e-12 * s < min_step) continue;
      bool ok = true;
      for (const auto& [lo, hi] : ranges) ok = ok && intervals(lo, hi, s) <= max_intervals;
      if (ok) return s;
    }
    step *= 10.0;
  }
  return step;
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
  // Equal axis scales: one step for both, and as many intervals on each (the shorter axis extended).
  const double step = nice_step({{x0, x1}, {y0, y1}}, 8, 0.0);
  const int64_t nx = intervals(x0, x1, step), ny = intervals(y0, y1, step), n = std::max<int64_t>(nx, ny);
  const AxisTicks xt = ticks_with_step(x0, x1, step, n - nx), yt = ticks_with_step(y0, y1, step, n - ny);
  Chart c = make_chart(xt, yt, 0, 0);
  constexpr double kPlot = 480.0;  // square plot area
  c.f.w = c.f.left + kPlot + c.f.right;
  c.f.h = c.f.top + kPlot + c.f.bottom;
  const Frame& f = c.f;
  const auto xy = [](const std::vector<EvalResult::Sample>& v) {
    std::vector<std::pair<double, double>> o;
    for (const auto& s : v) o.emplace_back(s.p.x(), s.p.y());
    return o;
  };
  std::string s = svg_open("topdown", f) + axes(c, "x, east (m)", "y, north (m)");
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
  double emax = 0.0;
  for (const auto& [t, e] : r.localization_error_over_time) emax = std::max(emax, e);
  for (const auto& [t, e] : r.formation_error_over_time) emax = std::max(emax, e);
  const Chart c =
      make_chart(nice_ticks(0.0, std::max(r.duration_s, 1.0), 10), nice_ticks(0.0, std::max(emax, 0.1), 6), 720, 300);
  const Frame& f = c.f;
  std::string s = svg_open("errors", f) + axes(c, "time since the first ground truth (s)", "error (m)");
  s += polyline(f, r.localization_error_over_time, "#d62728", 1.2);
  s += polyline(f, r.formation_error_over_time, "#2ca02c", 1.5);
  if (r.localization_error_over_time.empty() && r.formation_error_over_time.empty())
    s += no_data(f, "no matched leader estimates");
  return s + "</svg>";
}

std::string bin_label(const RangeBin& b) {
  return std::isinf(b.hi_m) ? fmt::format("{:g}+", b.lo_m) : fmt::format("{:g}-{:g}", b.lo_m, b.hi_m);
}

std::string range_chart(const EvalResult& r) {
  const auto& bins = r.localization_by_range;
  double ymax = 0.0;
  for (const auto& b : bins) ymax = std::max(ymax, b.error.rms);
  AxisTicks xt;  // categories 0..n, no ticks
  xt.hi = static_cast<double>(std::max<size_t>(bins.size(), 1));
  const Chart c = make_chart(xt, nice_ticks(0.0, std::max(ymax * 1.15, 0.1), 6), 720, 300, false);
  const Frame& f = c.f;
  std::string s = svg_open("error-by-range", f) + axes(c, "true range (m)", "RMS error (m)");
  bool any = false;
  for (size_t i = 0; i < bins.size(); ++i) {
    const auto& b = bins[i];
    const double xc = f.sx(static_cast<double>(i) + 0.5), bw = 0.6 * (f.sx(1.0) - f.sx(0.0));
    s += fmt::format(R"(<text x="{:.1f}" y="{:.1f}" font-size="11" text-anchor="middle">{}</text>)", xc,
                     f.h - f.bottom + 15, bin_label(b));
    if (b.error.n == 0) continue;
    any = true;
    s += fmt::format(R"(<rect class="data" x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="#9467bd">)"
                     R"(<title>{} m: RMS {:.3f} m, mean {:.3f} m, n = {}</title></rect>)",
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
  const Chart c = make_chart(nice_ticks(0.0, xmax, 10), nice_ticks(0.0, ymax, 6), 720, 340);
  const Frame& f = c.f;
  std::string s = svg_open("box-width", f) + axes(c, "truth range (m)", "box width (% of image width)");
  // At most ~1500 points per series, every k-th (deterministic).
  const size_t stride = std::max<size_t>(1, r.box_widths.size() / 1500);
  for (size_t i = 0; i < r.box_widths.size(); i += stride) {
    const auto& b = r.box_widths[i];
    s += fmt::format(R"(<circle class="data" cx="{:.1f}" cy="{:.1f}" r="2" fill="#7f7f7f" fill-opacity="0.6"/>)",
                     f.sx(b.range_m), f.sy(100.0 * b.w_truth_frac));
    s += fmt::format(R"(<circle class="data" cx="{:.1f}" cy="{:.1f}" r="2.2" fill="{}" fill-opacity="0.7"/>)",
                     f.sx(b.range_m), f.sy(100.0 * b.w_det_frac), b.redetected ? "#ff7f0e" : "#1f77b4");
  }
  if (r.box_widths.empty()) s += no_data(f, "no detections matched to the leader's truth box");
  return s + "</svg>";
}

std::string latency_chart(const EvalResult& r) {
  const auto& v = r.latency_samples_ms;
  AxisTicks xt = nice_ticks(0.0, 1.0, 8);
  if (!v.empty()) {
    xt = nice_ticks(std::min(0.0, *std::min_element(v.begin(), v.end())), *std::max_element(v.begin(), v.end()), 8);
  }
  // Bins of a round width: a quarter of a step of 1 or 2, a fifth of a step of 5.
  const int sub = mantissa(xt.step) == 5.0 ? 5 : 4;
  const double bin = xt.step / sub;
  const int bins = std::max(1, static_cast<int>(std::lround((xt.hi - xt.lo) / bin)));
  std::vector<int64_t> count(static_cast<size_t>(bins), 0);
  for (const double x : v) {
    const int i = std::clamp(static_cast<int>(std::floor((x - xt.lo) / bin)), 0, bins - 1);
    ++count[static_cast<size_t>(i)];
  }
  const int64_t cmax = std::max<int64_t>(1, *std::max_element(count.begin(), count.end()));
  const Chart c = make_chart(xt, nice_ticks(0.0, static_cast<double>(cmax), 5, 1.0), 720, 300);
  const Frame& f = c.f;
  std::string s = svg_open("latency", f) + axes(c, "exposure to published target (ms)", "targets_t messages (count)");
  for (int i = 0; i < bins; ++i) {
    if (count[static_cast<size_t>(i)] == 0) continue;
    const double a = xt.lo + bin * i, b = xt.lo + bin * (i + 1);
    const double n = static_cast<double>(count[static_cast<size_t>(i)]);
    s += fmt::format(R"(<rect class="data" x="{:.1f}" y="{:.1f}" width="{:.1f}" height="{:.1f}" fill="#8c564b">)"
                     R"(<title>{:g}-{:g} ms: {}</title></rect>)",
                     f.sx(a) + 0.5, f.sy(n), std::max(0.5, f.sx(b) - f.sx(a) - 1.0), f.sy(0.0) - f.sy(n), a, b,
                     count[static_cast<size_t>(i)]);
  }
  if (v.empty()) s += no_data(f, "no latency samples (no targets with a matching exposure)");
  return s + "</svg>";
}

/// Metres as the headline shows them: 3 decimals below 1 m, 2 below 100 m, none above.
std::string metres(double v) {
  const double a = std::abs(v);
  return fmt::format("{:.{}f} m", v, a < 1.0 ? 3 : a < 100.0 ? 2 : 0);
}

std::string milliseconds(double v) {
  return std::abs(v) < 1000.0 ? fmt::format("{:.1f} ms", v) : fmt::format("{:.2f} s", v / 1000.0);
}

std::string headline_table(const std::vector<HeadlineItem>& items) {
  std::string s =
      "<table id=\"headline\"><tr><th>figure</th><th>this flight</th><th>thesis (2018, real flights)</th></tr>\n";
  for (const auto& h : items) {
    s += fmt::format(
        "<tr data-key=\"{}\" data-measured=\"{}\"><td>{}</td><td><span class=\"v{}\">{}</span>"
        "<div class=\"d\">{}</div></td><td class=\"t\">{}</td></tr>\n",
        h.key, h.measured ? 1 : 0, escape_html(h.label), h.measured ? "" : " nm", escape_html(h.text),
        escape_html(h.detail), h.thesis.empty() ? "&mdash;" : escape_html(h.thesis));
  }
  return s + "</table>\n";
}

}  // namespace

AxisTicks nice_ticks(double lo, double hi, int max_intervals, double min_step) {
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0.0, hi = 1.0;
  if (hi < lo) std::swap(lo, hi);
  if (hi == lo) hi = lo + (lo == 0.0 ? 1.0 : std::abs(lo) / 10.0);
  return ticks_with_step(lo, hi, nice_step({{lo, hi}}, max_intervals, std::max(0.0, min_step)));
}

std::string tick_label(double value, double step) {
  step = std::abs(step);
  double scale = 1.0;
  const char* suffix = "";
  if (step >= 1e6) {
    scale = 1e6, suffix = "M";
  } else if (step >= 1e3) {
    scale = 1e3, suffix = "k";
  }
  const double s = step / scale, v = value / scale;
  const int decimals = s > 0.0 && s < 1.0 ? static_cast<int>(std::ceil(-std::log10(s) - 1e-9)) : 0;
  std::string out = fmt::format("{:.{}f}", v, decimals);
  if (out.find_first_not_of("-0.") == std::string::npos && out[0] == '-') out.erase(0, 1);  // no "-0"
  return out + suffix;
}

std::vector<HeadlineItem> report_headline(const EvalResult& r) {
  std::vector<HeadlineItem> h;
  const auto not_measured = [](HeadlineItem& i, const std::string& why) {
    i.measured = false;
    i.values.clear();
    i.text = "not measured";
    i.detail = why;
  };
  const std::string no_truth = "the log has no ground truth";
  {
    HeadlineItem i{"localization_rms",
                   "Localization error, 3-D RMS",
                   true,
                   {r.localization.rms},
                   metres(r.localization.rms),
                   fmt::format("|estimate - truth| of {} world-valid target(s) matched to a vehicle; max {}",
                               r.localization.n, metres(r.localization.max)),
                   "2.86 m (RMS, average of its formation flights against RTK-GPS)"};
    if (r.truth_frames == 0) {
      not_measured(i, no_truth);
    } else if (r.localization.n == 0) {
      not_measured(i, "no world-valid target matched to a vehicle");
    }
    h.push_back(i);
  }
  {
    HeadlineItem i{"formation_rms",
                   "Formation error, horizontal RMS",
                   true,
                   {r.formation_horizontal.rms},
                   metres(r.formation_horizontal.rms),
                   fmt::format("follower minus its desired position, {} ground-truth frames after settling; vertical "
                               "RMS {}",
                               r.formation_horizontal.n, metres(r.formation_vertical.rms)),
                   ""};
    if (r.truth_frames == 0) {
      not_measured(i, no_truth);
    } else if (r.formation_horizontal.n == 0) {
      not_measured(i,
                   "no formation target given (--scenario with --follower-config, or --formation-offset), or no "
                   "frame after --settle");
    }
    h.push_back(i);
  }
  {
    const double pct = r.frames_leader_visible > 0 ? 100.0 * static_cast<double>(r.frames_leader_detected) /
                                                         static_cast<double>(r.frames_leader_visible)
                                                   : 0.0;
    HeadlineItem i{"detection_rate",
                   "Leader detected",
                   true,
                   {static_cast<double>(r.frames_leader_detected), static_cast<double>(r.frames_leader_visible)},
                   fmt::format("{} of {} frames ({:.1f} %)", r.frames_leader_detected, r.frames_leader_visible, pct),
                   fmt::format("frames where the leader is visible with a box on it (centred in its truth box; boxes "
                               "elsewhere do not count); {} false box(es) in {} of those frames",
                               r.false_boxes_leader_visible, r.frames_leader_visible_with_false_box),
                   ""};
    if (r.detection_source == "ground_truth") i.detail += "; boxes from simulator ground truth, not a detector";
    if (r.truth_frames == 0) {
      not_measured(i, no_truth);
    } else if (r.frames_leader_visible == 0) {
      not_measured(i, "the leader is visible in no ground-truth frame");
    } else if (r.detection_frames == 0) {
      not_measured(i, "the log has no detections_t");
    }
    h.push_back(i);
  }
  const bool any_target = r.target_estimates + r.false_targets > 0;
  {
    HeadlineItem i{
        "false_targets",
        "False targets",
        true,
        {static_cast<double>(r.false_targets), static_cast<double>(r.false_track_ids)},
        r.false_targets == 0 ? std::string("0")
                             : fmt::format("{} in {} track id(s)", r.false_targets, r.false_track_ids),
        fmt::format("world-valid targets farther than the match radius from every vehicle; {:.3f} per second",
                    r.false_targets_per_s),
        ""};
    if (r.truth_frames == 0) {
      not_measured(i, no_truth);
    } else if (!any_target) {
      not_measured(i, "the log has no world-valid target");
    }
    h.push_back(i);
  }
  {
    HeadlineItem i{
        "track_ids",
        "Track ids on the leader",
        true,
        {static_cast<double>(r.track_ids_on_leader), static_cast<double>(r.leader_id_switches)},
        fmt::format("{}, {} id switch(es)", r.track_ids_on_leader, r.leader_id_switches),
        fmt::format("distinct track ids matched to the leader over {} matched target(s)", r.target_estimates),
        ""};
    if (r.truth_frames == 0) {
      not_measured(i, no_truth);
    } else if (r.target_estimates == 0) {
      not_measured(i, "no world-valid target matched to a vehicle");
    }
    h.push_back(i);
  }
  {
    HeadlineItem i{"latency",
                   "End-to-end latency, p50 / p99",
                   true,
                   {r.latency_ms.p50, r.latency_ms.p99},
                   milliseconds(r.latency_ms.p50) + " / " + milliseconds(r.latency_ms.p99),
                   fmt::format("exposure to published targets_t, wall clock as logged; {} sample(s), max {}",
                               r.latency_ms.n, milliseconds(r.latency_ms.max)),
                   "about 0.7 s lag in flight (0.13 s camera, 0.27-0.56 s network)"};
    if (r.latency_ms.n == 0) not_measured(i, "no targets_t with a matching exposure in the log");
    h.push_back(i);
  }
  return h;
}

std::vector<ReportFrame> draw_report_frames(const EvalResult& r, const EvalOptions& o) {
  std::vector<ReportFrame> out;
  // The full images when the log has them, else the camera's previews (small JPEGs, boxes scaled to them).
  const bool previews = r.image_utimes.empty();
  const std::string& channel = previews ? o.preview_channel : o.image_channel;
  const size_t n = previews ? r.preview_utimes.size() : r.image_utimes.size();
  if (n == 0 || o.report_frames <= 0) return out;
  std::set<size_t> wanted;  // indices among the image events, spread evenly
  const size_t k = std::min(n, static_cast<size_t>(o.report_frames));
  for (size_t i = 0; i < k; ++i) wanted.insert(k == 1 ? n / 2 : (i * (n - 1) + (k - 1) / 2) / (k - 1));
  common::LcmLogReader file(o.log);  // a corrupt event throws, naming its byte offset
  common::Progress progress = log_progress(o.progress, "wingman: drawing frames from " + o.log, o.log);
  size_t index = 0;
  while (const common::LcmLogEvent* ev = file.read_next()) {
    progress.update(ev->offset);
    if (ev->channel != channel ||
        lcm_fingerprint(ev->data, ev->datalen) != static_cast<uint64_t>(wingman::image_t::getHash()))
      continue;
    const size_t i = index++;
    if (!wanted.count(i)) continue;
    wingman::image_t img;
    if (img.decode(ev->data, 0, ev->datalen) < 0) continue;
    cv::Mat bgr = detector::image_to_bgr(img, nullptr);
    if (bgr.empty()) continue;
    const auto fi = r.frames.find(img.utime);
    // Boxes are in the source image's pixels: a preview is that image scaled down (its detections say how wide).
    const double source_w =
        previews ? (fi != r.frames.end() && fi->second.image_width > 0 ? fi->second.image_width : 0.0) : bgr.cols;
    // Scaled down first, then drawn on: lines and text stay legible on the thumbnail.
    const double shrink =
        bgr.cols > kReportThumbnailWidth ? static_cast<double>(kReportThumbnailWidth) / bgr.cols : 1.0;
    const double scale = source_w > 0 ? shrink * bgr.cols / source_w : 0.0;
    if (shrink < 1.0) {
      cv::resize(bgr, bgr,
                 cv::Size(kReportThumbnailWidth, std::max(1, static_cast<int>(std::lround(bgr.rows * shrink)))), 0, 0,
                 cv::INTER_AREA);
    }
    const int thick = bgr.cols >= 240 ? 2 : 1;
    const auto rect = [scale](const EvalResult::FrameInfo::Box& b) {
      const auto px = [scale](double v) { return static_cast<int>(std::lround(v * scale)); };
      return cv::Rect(cv::Point(px(b.cx - b.w / 2), px(b.cy - b.h / 2)),
                      cv::Point(px(b.cx + b.w / 2), px(b.cy + b.h / 2)));
    };
    if (fi != r.frames.end() && scale > 0) {
      for (const auto& b : fi->second.truth_boxes) {
        if (b.camera_id != img.camera_id || !b.flag) continue;
        const bool leader = b.vehicle_id == o.leader_id;
        cv::rectangle(bgr, rect(b), leader ? cv::Scalar(0, 200, 0) : cv::Scalar(160, 160, 160), thick);
        if (leader && fi->second.leader_track_id >= 0) {
          cv::putText(bgr, fmt::format("track {}", fi->second.leader_track_id),
                      cv::Point(rect(b).x, std::max(12, rect(b).y - 4)), cv::FONT_HERSHEY_SIMPLEX, 0.4,
                      cv::Scalar(0, 200, 0), 1, cv::LINE_AA);
        }
      }
      for (const auto& b : fi->second.detections) {
        if (b.camera_id != img.camera_id) continue;
        cv::rectangle(bgr, rect(b), b.flag ? cv::Scalar(14, 127, 255) : cv::Scalar(40, 39, 214), thick);
      }
    }
    std::vector<uint8_t> jpeg;
    if (!cv::imencode(".jpg", bgr, jpeg, {cv::IMWRITE_JPEG_QUALITY, 80})) continue;
    out.push_back(
        {static_cast<double>(img.utime - r.first_truth_utime) * 1e-6, img.utime, base64(jpeg), bgr.cols, bgr.rows});
    if (i >= *wanted.rbegin()) break;
  }
  progress.finish();
  return out;
}

std::string html_report(const EvalResult& r, const EvalOptions& o, const std::vector<ReportFrame>& frames) {
  std::string html = "<!DOCTYPE html>\n<html><head><meta charset=\"utf-8\"><title>" + escape_html(o.title) +
                     "</title>\n<style>body{font-family:sans-serif;margin:24px;color:#222} pre{background:#f4f4f4;"
                     "padding:12px;overflow-x:auto} code{white-space:nowrap} "
                     ".k{display:inline-block;width:14px;height:4px;margin:0 6px 3px 12px}"
                     " figure{display:inline-block;margin:4px;vertical-align:top} figcaption{font-size:12px}"
                     " img.frame{width:" +
                     std::to_string(kReportThumbnailWidth) +
                     "px;max-width:100%;height:auto}"
                     " #headline{border-collapse:collapse;margin:8px 0 16px} #headline th{text-align:left;"
                     "font-weight:normal;color:#666;font-size:13px;padding:4px 18px 4px 0;border-bottom:1px solid #ccc}"
                     " #headline td{padding:6px 18px 6px 0;vertical-align:top;border-bottom:1px solid #eee}"
                     " #headline .v{font-size:22px;font-weight:bold} #headline .v.nm{font-size:16px;color:#999;"
                     "font-weight:normal;font-style:italic} #headline .d{font-size:12px;color:#666;max-width:560px}"
                     " #headline .t{font-size:14px;color:#444;max-width:260px}</style>"
                     "</head><body>\n";
  html += "<h1>" + escape_html(o.title) + "</h1>\n";
  if (r.detection_source == "ground_truth") {
    html +=
        "<p><b>Detections came from simulator ground truth</b> (no trained detector model was used): these "
        "numbers measure localization, tracking and control, not detection.</p>\n";
  }
  html += fmt::format("<p>Log: <code>{}</code>; {:.1f} s of ground truth ({} frames); detections from {}.</p>\n",
                      escape_html(o.log), r.duration_s, r.truth_frames, escape_html(r.detection_source));
  html += headline_table(report_headline(r));
  html += "<h2>Camera frames</h2>\n";
  if (r.image_utimes.empty() && r.preview_utimes.empty()) {
    html += "<p id=\"no-images\">This log has no camera images on <code>" + escape_html(o.image_channel) +
            "</code> and no previews on <code>" + escape_html(o.preview_channel) +
            "</code>: the flight ran without rendering (<code>tools/fly.sh</code> records the camera's 1 Hz preview "
            "always, the full images only with <code>--record-images</code>).</p>\n";
  } else {
    html += (r.image_utimes.empty()
                 ? fmt::format("<p>{} of the log's {} previews (<code>{}</code>: the camera's monitoring preview, "
                               "about 1 per second; the full images are not in the log), evenly spaced. ",
                               frames.size(), r.preview_utimes.size(), escape_html(o.preview_channel))
                 : fmt::format("<p>{} of the log's {} images, evenly spaced. ", frames.size(), r.image_utimes.size())) +
            key("#00c800", "truth box (leader, with its matched track id)") + key("#a0a0a0", "truth box (other)") +
            key("#d62728", "detection, single pass") + key("#ff7f0e", "detection, zoom-in or window") +
            "</p>\n<div id=\"frames\">\n";
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
  html += "<h2>Top-down view</h2><p>" + key("#1f77b4", "leader truth") + key("#d62728", "leader estimate") +
          key("#2ca02c", "follower") + "</p>\n" + topdown_chart(r) + "\n";
  html += "<h2>Errors over time</h2><p>" + key("#d62728", "localization |e| (leader)") +
          key("#2ca02c", "formation, horizontal") + "</p>\n" + errors_chart(r) + "\n";
  html +=
      "<h2>Localization error by range</h2><p>RMS of |estimate - truth| by the true follower-to-target "
      "distance.</p>\n" +
      range_chart(r) + "\n";
  html += "<h2>Box width over distance</h2><p>" + key("#7f7f7f", "truth (projected)") +
          key("#1f77b4", "detection, single pass") + key("#ff7f0e", "detection, zoom-in or window") + "</p>\n" +
          box_width_chart(r) + "\n";
  html +=
      "<h2>Latency</h2><p>From the exposure (the earlier log-event time of the image and the ground truth of the "
      "target's source_utime) to the published targets_t, wall clock as recorded by the logger.</p>\n" +
      latency_chart(r) + "\n";
  html += "<h2>All numbers</h2>\n<pre id=\"numbers\">" + escape_html(r.report()) + "</pre>\n";
  return html + "</body></html>\n";
}

void write_html_report(const EvalResult& r, const EvalOptions& o, const std::string& path) {
  const std::string html = html_report(r, o, draw_report_frames(r, o));
  std::ofstream f(path);
  f << html;
  if (!f) throw std::runtime_error("wingman report: cannot write '" + path + "'");
}

}  // namespace wingman::tools
