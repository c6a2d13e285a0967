// SPDX-License-Identifier: MIT
// localize_box(): exact tangent-plane localization of a sphere (default) or the thesis's eq. 24 + 32/33.
//
// Exact method. A box edge, e.g. the left one u = u_l, back-projects (pinhole) to the plane through the camera
// centre with unit normal n_l ∝ (1, 0, -(u_l - c_x) / f_x), oriented towards the box interior. The sphere touches
// that plane, so its centre c satisfies n_l . c = r; the four edges give N c = r 1 (4 equations, 3 unknowns),
// solved by least squares, exact for a pinhole. With distortion the image line u = u_l back-projects to a curved
// surface; the sphere touches it along one ray, where the silhouette touches the line, so the plane used is the
// surface's tangent plane along that ray: spanned by the ray through (u_l, s) and the derivative of the ray
// along the line, at the tangency coordinate s. s starts at the box centre and is updated from the current
// solution (the tangency point c - r n projects to (u_l, s)); a few iterations converge.
//
// Covariance. The measured quantities are the four edges e = (u_l, u_r, v_t, v_b). The noise model is
//   S = diag(s_u^2, s_u^2, s_v^2, s_v^2) + sigma_c^2 blockdiag([1 1; 1 1], [1 1; 1 1]),
//   s_u^2 = sigma_e^2 + (rel w)^2, s_v^2 = sigma_e^2 + (rel h)^2 (noise.edge_px, noise.edge_rel; w, h the box's size)
// (independent edge noise plus a common shift of the whole box per axis), propagated to first order:
//   cov_p = J S J^T,  J = dp/de  (central differences, +-0.05 px).
// For the exact method the tangency coordinates s are held fixed while differentiating: the constraint
// "distance from c to the back-projected edge = r" is stationary in s at the tangency (envelope theorem), so this
// is the full first-order derivative. Near the optical axis of a pinhole this gives, with l the range and f the
// focal length: var(range) ≈ sigma_e^2 l^4 / (4 f^2 r^2) (exact, four edges), sigma_e^2 l^4 / (2 f^2 r^2) (thesis,
// width only); lateral variance per axis ≈ l^2 (sigma_c^2 + sigma_e^2 / 2) / f^2.
#include "wingman/localizer/sphere_localizer.hpp"

#include <wingman/geometry/sphere_projection.hpp>
#include "wingman/localizer/thesis_range.hpp"

#include <fmt/format.h>
#include <Eigen/Dense>
#include <wingman/common/config.hpp>

#include <algorithm>
#include <array>
#include <cmath>

namespace wingman::localizer {

std::vector<std::string> SphereLocalizerOptions::validate() const {
  using common::problem;
  std::vector<std::string> p;
  if (!(std::isfinite(radius_m) && radius_m > 0)) p.push_back(problem("target.radius_m", radius_m, "must be > 0"));
  try {
    (void)BoxRelation::load(box_relation);
  } catch (const BoxRelationError& e) {
    p.push_back(problem("target.box_relation", box_relation, e.what()));
  }
  if (range_method != "exact" && range_method != "thesis" && range_method != "thesis_eq33")
    p.push_back(problem("range.method", range_method, "must be exact, thesis or thesis_eq33"));
  if (!(std::isfinite(min_range_m) && min_range_m > radius_m))
    p.push_back(problem("range.min_m", min_range_m, fmt::format("must be > target.radius_m = {}", radius_m)));
  if (!(std::isfinite(max_range_m) && max_range_m > min_range_m))
    p.push_back(problem("range.max_m", max_range_m, fmt::format("must be finite and > range.min_m = {}", min_range_m)));
  if (!(std::isfinite(edge_noise_px) && edge_noise_px > 0))
    p.push_back(problem("noise.edge_px", edge_noise_px, "must be > 0"));
  if (!(std::isfinite(edge_noise_rel) && edge_noise_rel >= 0))
    p.push_back(problem("noise.edge_rel", edge_noise_rel, "must be >= 0"));
  if (!(std::isfinite(centre_noise_px) && centre_noise_px >= 0))
    p.push_back(problem("noise.centre_px", centre_noise_px, "must be >= 0"));
  if (!(std::isfinite(border_margin_px) && border_margin_px >= 0))
    p.push_back(problem("border.margin_px", border_margin_px, "must be >= 0"));
  return p;
}

RangeMethod SphereLocalizerOptions::method() const {
  if (range_method == "thesis") return RangeMethod::kThesis;
  if (range_method == "thesis_eq33") return RangeMethod::kThesisEq33;
  return RangeMethod::kExact;
}

namespace {

// Edge indices; left and right are lines of constant u, top and bottom of constant v.
constexpr int kLeft = 0, kRight = 1, kTop = 2, kBottom = 3;
constexpr double kJacobianStepPx = 0.05;

/// Box edges and centre in calibration pixel coordinates.
struct Edges {
  std::array<double, 4> e;  // u_l, u_r, v_t, v_b
  Eigen::Vector2d centre() const { return {0.5 * (e[kLeft] + e[kRight]), 0.5 * (e[kTop] + e[kBottom])}; }
};

/// The pixel of edge i at tangency coordinate s (v for left/right, u for top/bottom).
Eigen::Vector2d edge_point(int i, double e_i, double s) {
  return i < kTop ? Eigen::Vector2d(e_i, s) : Eigen::Vector2d(s, e_i);
}

/// Unit normal of the plane through the camera centre tangent to the back-projection of edge i at coordinate s,
/// oriented so that the ray `interior` (the box centre's) is on its positive side.
Eigen::Vector3d edge_normal(const geometry::CameraModel& camera, int i, double e_i, double s,
                            const Eigen::Vector3d& interior) {
  Eigen::Vector3d n;
  if (camera.distortion() == geometry::Distortion::kNone) {
    n = i < kTop ? Eigen::Vector3d(1, 0, -(e_i - camera.cx()) / camera.fx())
                 : Eigen::Vector3d(0, 1, -(e_i - camera.cy()) / camera.fy());
  } else {
    const Eigen::Vector2d along = i < kTop ? Eigen::Vector2d(0, 1) : Eigen::Vector2d(1, 0);
    const Eigen::Vector2d uv = edge_point(i, e_i, s);
    constexpr double h = 1.0;  // px; the back-projected line is smooth, O(h^2) error is negligible
    const Eigen::Vector2d x0 = camera.undistort_to_normalized(uv);
    const Eigen::Vector2d xp = camera.undistort_to_normalized(uv + h * along);
    const Eigen::Vector2d xm = camera.undistort_to_normalized(uv - h * along);
    const Eigen::Vector3d ray(x0.x(), x0.y(), 1.0);
    const Eigen::Vector3d tangent(xp.x() - xm.x(), xp.y() - xm.y(), 0.0);
    n = ray.cross(tangent);
  }
  n.normalize();
  return n.dot(interior) < 0 ? Eigen::Vector3d(-n) : n;
}

/// What a solve gives: the centre, or only a bearing.
struct Solution {
  bool range_valid = false;
  bool ok = true;      // false: no sphere fits (reason set)
  std::string reason;  // when !ok
  Eigen::Vector3d p_in_cam = Eigen::Vector3d::Zero();
  Eigen::Vector3d bearing = Eigen::Vector3d::UnitZ();
};

/// The distance of each edge's plane from the sphere's centre, metres: radius x the box relation's width ratio for
/// the left and right edges, x its height ratio for the top and bottom ones (a model's box is the box of a
/// concentric sphere that much larger or smaller; BoxScale).
using EdgeRadii = std::array<double, 4>;

EdgeRadii edge_radii(double radius, const BoxScale& scale) {
  return {radius * scale.width_ratio, radius * scale.width_ratio, radius * scale.height_ratio,
          radius * scale.height_ratio};
}

/// Exact solve from edge-plane normals (uncut edges only) and the box-centre ray; radii per edge in metres.
Solution solve_planes(const std::array<Eigen::Vector3d, 4>& normals, const std::array<bool, 4>& whole,
                      const Eigen::Vector3d& centre_ray, const EdgeRadii& radii) {
  Solution out;
  out.bearing = centre_ray;
  Eigen::Matrix<double, Eigen::Dynamic, 3, 0, 4, 3> N(0, 3);
  int count = 0;
  for (int i = 0; i < 4; ++i) count += whole[i] ? 1 : 0;
  N.resize(count, 3);
  Eigen::Matrix<double, Eigen::Dynamic, 1, 0, 4, 1> d(count);
  int row = 0;
  for (int i = 0; i < 4; ++i) {
    if (!whole[i]) continue;
    d(row) = radii[i];
    N.row(row++) = normals[i].transpose();
  }
  if (count >= 3) {
    const Eigen::Matrix3d NtN = N.transpose() * N;
    const Eigen::Vector3d Ntr = N.transpose() * d;  // N^T (r_i)
    out.p_in_cam = NtN.ldlt().solve(Ntr);
  } else if (count == 2 && ((whole[kLeft] && whole[kRight]) || (whole[kTop] && whole[kBottom]))) {
    // The centre lies on the line {c : n_a . c = r, n_b . c = r}; take its point closest to the centre ray.
    const Eigen::Vector3d na = N.row(0).transpose(), nb = N.row(1).transpose();
    const Eigen::Vector3d m = na.cross(nb).normalized();
    Eigen::Matrix2d G;
    G << 1, na.dot(nb), na.dot(nb), 1;
    const Eigen::Vector2d w = G.ldlt().solve(Eigen::Vector2d(d(0), d(1)));
    const Eigen::Vector3d c0 = w(0) * na + w(1) * nb;  // the line's point closest to the camera
    // min over (t, k) of |c0 + t m - k b|^2.
    const double mb = m.dot(centre_ray);
    Eigen::Matrix2d A;
    A << 1, -mb, -mb, 1;
    const Eigen::Vector2d tk = A.ldlt().solve(Eigen::Vector2d(-m.dot(c0), centre_ray.dot(c0)));
    out.p_in_cam = c0 + tk(0) * m;
  } else {
    return out;  // bearing only
  }
  if (!(out.p_in_cam.allFinite() && out.p_in_cam.z() > 0 &&
        out.p_in_cam.norm() > *std::max_element(radii.begin(), radii.end()))) {
    out.ok = false;
    out.reason = "no sphere in front of the camera fits the box edges";
    return out;
  }
  out.range_valid = true;
  out.bearing = out.p_in_cam.normalized();
  return out;
}

/// The exact method's state: the tangency coordinate of each edge and the edge-plane normals.
struct ExactState {
  std::array<double, 4> s{};
  std::array<Eigen::Vector3d, 4> normals;
  Eigen::Vector3d centre_ray;
  int iterations = 0;
};

Solution solve_exact(const geometry::CameraModel& camera, const Edges& edges, const std::array<bool, 4>& whole,
                     const EdgeRadii& radii, ExactState& state) {
  const Eigen::Vector2d centre = edges.centre();
  state.centre_ray = camera.unproject(centre);
  state.s = {centre.y(), centre.y(), centre.x(), centre.x()};
  const bool distorted = camera.distortion() != geometry::Distortion::kNone;
  Solution solution;
  for (state.iterations = 1; state.iterations <= 30; ++state.iterations) {
    for (int i = 0; i < 4; ++i)
      if (whole[i]) state.normals[i] = edge_normal(camera, i, edges.e[i], state.s[i], state.centre_ray);
    solution = solve_planes(state.normals, whole, state.centre_ray, radii);
    if (!distorted || !solution.ok || !solution.range_valid) break;
    // New tangency coordinates: where the silhouette of the sphere at the current centre is extremal (the point
    // the measured edge should touch). Taken from the forward model, which depends on c only; using the plane's
    // own tangency point c - r n instead can oscillate and diverge near the rim of a fisheye.
    // The silhouette of the sphere of the mean edge radius (the ratios differ by tens of percent at most, and the
    // tangency coordinate moves little with the radius).
    const double radius = 0.25 * (radii[0] + radii[1] + radii[2] + radii[3]);
    const geometry::SphereImageBox image = geometry::project_sphere(camera, solution.p_in_cam, radius, 1e-3);
    if (!image.valid) {
      solution.ok = false;
      solution.reason = "no sphere in front of the camera fits the box edges (" + image.reason + ")";
      return solution;
    }
    double change = 0;
    for (int i = 0; i < 4; ++i) {
      if (!whole[i]) continue;
      const Eigen::Vector2d uv = camera.project(image.tangent_ray_in_cam[i]);
      const double s_new = i < kTop ? uv.y() : uv.x();
      change = std::max(change, std::abs(s_new - state.s[i]));
      state.s[i] = s_new;
    }
    if (change < 1e-6) break;
  }
  state.iterations = std::min(state.iterations, 30);
  return solution;
}

/// The thesis's method: eq. 24 direction of the box centre, eq. 27-32 (or eq. 33) distance from the rays
/// through the midpoints of the left and right edges (top and bottom if the width is cut).
Solution solve_thesis(const geometry::CameraModel& camera, const Edges& edges, const std::array<bool, 4>& whole,
                      const EdgeRadii& radii, bool eq33, int& edges_used) {
  Solution out;
  const Eigen::Vector2d centre = edges.centre();
  out.bearing = thesis_direction(camera.undistort_to_normalized(centre));  // eq. 24
  Eigen::Vector3d a, b;
  double radius = radii[kLeft];
  if (whole[kLeft] && whole[kRight]) {
    a = camera.unproject({edges.e[kLeft], centre.y()});
    b = camera.unproject({edges.e[kRight], centre.y()});
  } else if (whole[kTop] && whole[kBottom]) {
    a = camera.unproject({centre.x(), edges.e[kTop]});
    b = camera.unproject({centre.x(), edges.e[kBottom]});
    radius = radii[kTop];
  } else {
    edges_used = 0;
    return out;  // bearing only
  }
  edges_used = 2;
  const double alpha = thesis_half_angle(a, b);
  if (!(alpha > 0 && alpha < M_PI / 2)) {
    out.ok = false;
    out.reason = fmt::format("the box spans {} degrees: no sphere fits", 2 * alpha * 180 / M_PI);
    return out;
  }
  const double range = eq33 ? thesis_range_eq33(radius, alpha) : thesis_range_eq32(radius, alpha);
  out.p_in_cam = range * out.bearing;
  out.range_valid = true;
  return out;
}

std::string check_box(const geometry::PixelBox& box, const geometry::CameraModel& camera) {
  const std::pair<const char*, double> fields[] = {
      {"box.cx", box.cx}, {"box.cy", box.cy}, {"box.w", box.w}, {"box.h", box.h}};
  for (const auto& [name, value] : fields)
    if (!std::isfinite(value)) return fmt::format("{} = {}: must be finite", name, value);
  if (!(box.w > 0)) return fmt::format("box.w = {}: must be > 0", box.w);
  if (!(box.h > 0)) return fmt::format("box.h = {}: must be > 0", box.h);
  if (box.cx < 0 || box.cx > camera.width())
    return fmt::format("box.cx = {}: outside the image [0, {}]", box.cx, camera.width());
  if (box.cy < 0 || box.cy > camera.height())
    return fmt::format("box.cy = {}: outside the image [0, {}]", box.cy, camera.height());
  return "";
}

}  // namespace

LocalizeResult localize_box(const geometry::PixelBox& box, const geometry::CameraModel& camera,
                            const SphereLocalizerOptions& options, const BoxScale& scale) {
  LocalizeResult result;
  if (std::string bad = check_box(box, camera); !bad.empty()) {
    result.reason = std::move(bad);
    return result;
  }
  // Border rule, in PixelBox coordinates (the image spans [0, width] x [0, height]).
  const double m = options.border_margin_px;
  const double left = box.cx - 0.5 * box.w, right = box.cx + 0.5 * box.w;
  const double top = box.cy - 0.5 * box.h, bottom = box.cy + 0.5 * box.h;
  const std::array<bool, 4> whole = {left > m, right<camera.width() - m, top> m, bottom < camera.height() - m};
  Edges edges{{left - geometry::kBoxToCameraPixel, right - geometry::kBoxToCameraPixel,
               top - geometry::kBoxToCameraPixel, bottom - geometry::kBoxToCameraPixel}};

  const RangeMethod method = options.method();
  const EdgeRadii r = edge_radii(options.radius_m, scale);
  Solution solution;
  ExactState state;
  if (method == RangeMethod::kExact) {
    solution = solve_exact(camera, edges, whole, r, state);
    result.iterations = state.iterations;
    result.edges_used = 0;
    if (solution.range_valid)
      for (bool w : whole) result.edges_used += w ? 1 : 0;
  } else {
    solution = solve_thesis(camera, edges, whole, r, method == RangeMethod::kThesisEq33, result.edges_used);
  }
  if (!solution.ok) {
    result.reason = solution.reason;
    return result;
  }
  CameraMeasurement& out = result.measurement;
  out.bearing_in_cam = solution.bearing;
  out.range_valid = solution.range_valid;
  if (!solution.range_valid) {
    out.range = 0;
    out.p_target_in_cam.setZero();
    out.cov_p_in_cam.setZero();
    result.edges_used = 0;
    result.ok = true;
    return result;
  }
  out.p_target_in_cam = solution.p_in_cam;
  out.range = solution.p_in_cam.norm();
  if (out.range < options.min_range_m || out.range > options.max_range_m) {
    result.reason = fmt::format("range {:.3f} m outside [range.min_m, range.max_m] = [{}, {}] m", out.range,
                                options.min_range_m, options.max_range_m);
    return result;
  }

  // Covariance: J (3x4) by central differences over the edges, S as documented at the top of this file.
  auto perturbed_position = [&](int i, double delta) -> Eigen::Vector3d {
    Edges perturbed = edges;
    perturbed.e[i] += delta;
    Solution s;
    if (method == RangeMethod::kExact) {
      // Tangency coordinates held fixed (envelope theorem): only edge i's plane and the centre ray change.
      std::array<Eigen::Vector3d, 4> normals = state.normals;
      if (whole[i]) normals[i] = edge_normal(camera, i, perturbed.e[i], state.s[i], state.centre_ray);
      // The centre ray matters only with two whole edges (it fixes the point on their planes' line).
      s = solve_planes(normals, whole, result.edges_used >= 3 ? state.centre_ray : camera.unproject(perturbed.centre()),
                       r);
    } else {
      int unused = 0;
      s = solve_thesis(camera, perturbed, whole, r, method == RangeMethod::kThesisEq33, unused);
    }
    return s.range_valid ? s.p_in_cam : solution.p_in_cam;
  };
  Eigen::Matrix<double, 3, 4> J;
  for (int i = 0; i < 4; ++i)
    J.col(i) =
        (perturbed_position(i, kJacobianStepPx) - perturbed_position(i, -kJacobianStepPx)) / (2 * kJacobianStepPx);
  const double se2 = options.edge_noise_px * options.edge_noise_px;
  const double edge_rel = std::hypot(options.edge_noise_rel, scale.edge_noise_rel);
  const double rel_u = edge_rel * (edges.e[kRight] - edges.e[kLeft]);
  const double rel_v = edge_rel * (edges.e[kBottom] - edges.e[kTop]);
  const double sc2 = options.centre_noise_px * options.centre_noise_px;
  Eigen::Matrix4d S =
      Eigen::Vector4d(se2 + rel_u * rel_u, se2 + rel_u * rel_u, se2 + rel_v * rel_v, se2 + rel_v * rel_v).asDiagonal();
  S.block<2, 2>(0, 0).array() += sc2;
  S.block<2, 2>(2, 2).array() += sc2;
  out.cov_p_in_cam = J * S * J.transpose();
  // The box relation's spread: a relative error of the whole scale, along the line of sight (p is proportional to the
  // edge radii).
  out.cov_p_in_cam +=
      scale.range_sigma_rel * scale.range_sigma_rel * out.p_target_in_cam * out.p_target_in_cam.transpose();
  out.cov_p_in_cam = 0.5 * (out.cov_p_in_cam + out.cov_p_in_cam.transpose()).eval();
  result.ok = true;
  return result;
}

}  // namespace wingman::localizer
