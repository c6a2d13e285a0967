// SPDX-License-Identifier: MIT
// distractor_model(): procedural airplanes, birds and helicopters built from boxes, cylinders and tapered plates.
#include "wingman/sim/distractor_model.hpp"

#include "colour.hpp"
#include "mesh_builder.hpp"

#include <wingman/common/config.hpp>
#include <wingman/common/detection_class.hpp>

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace wingman::sim {
namespace {

constexpr int kRoundSegments = 10;  // fuselage, body and mast cross-sections
constexpr double kDeg = M_PI / 180.0;

Eigen::Vector4f rgba(const std::vector<double>& srgb, double scale = 1.0) {
  const Eigen::Vector3d c = detail::linear_colour(srgb) * scale;
  return Eigen::Vector4f(static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()), 1.0f);
}

/// A frame whose own z axis points along body +x (cylinders and prisms are built along their own z), at `t`.
Eigen::Isometry3d along_x(const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1,  //
      0, 1, 0,            //
      -1, 0, 0;           // own x -> body -z, own y -> body y, own z -> body x
  T.translation() = t;
  return T;
}

/// A frame whose own x-y plane is the body x-z plane (a fin seen from the side), at `t`; own z is body -y.
Eigen::Isometry3d upright(const Eigen::Vector3d& t) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 1, 0, 0,  //
      0, 0, -1,           //
      0, 1, 0;            // own x -> body x, own y -> body z, own z -> body -y
  T.translation() = t;
  return T;
}

/// One wing (or half tailplane) as a tapered plate of thickness `t`: root chord `c_root` centred at body x = `x_root`
/// on the side `side` (+1 left, -1 right) at y = side * `y_root`, reaching `length` outwards, its tip's leading edge
/// `sweep` metres behind the root's, raised `angle_rad` above the horizontal about the root's x axis.
void wing(detail::MeshBuilder& mb, int side, double x_root, double y_root, double length, double c_root, double c_tip,
          double sweep, double t, double angle_rad, const Eigen::Vector4f& colour) {
  // Polygon in the wing's own frame: x forward, y outward along the span; counter-clockwise seen from own +z.
  std::vector<Eigen::Vector2d> plate = {{0.5 * c_root, 0.0},
                                        {0.5 * c_root - sweep, length},
                                        {0.5 * c_root - sweep - c_tip, length},
                                        {-0.5 * c_root, 0.0}};
  if (side < 0) {  // mirrored in y: reverse the order to stay counter-clockwise
    for (Eigen::Vector2d& p : plate) p.y() = -p.y();
    std::swap(plate[0], plate[3]);
    std::swap(plate[1], plate[2]);
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(side * angle_rad, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x_root, side * y_root, 0.0);
  mb.prism(T, plate, -0.5 * t, 0.5 * t, colour, 0);
}

/// A fin: a tapered plate standing in the body x-z plane, root chord `c_root` with its trailing edge at body x =
/// `x_trailing`, height `height` above z = `z_root`, leading edge swept back by `sweep`.
void fin(detail::MeshBuilder& mb, double x_trailing, double z_root, double height, double c_root, double c_tip,
         double sweep, double t, const Eigen::Vector4f& colour) {
  const std::vector<Eigen::Vector2d> plate = {{x_trailing, z_root},
                                              {x_trailing + c_root, z_root},
                                              {x_trailing + c_root - sweep, z_root + height},
                                              {x_trailing + c_root - sweep - c_tip, z_root + height}};
  // Counter-clockwise in the fin's own x-y plane (body x forward, z up).
  mb.prism(upright(Eigen::Vector3d::Zero()), plate, -0.5 * t, 0.5 * t, colour, 0);
}

void build_airplane(detail::MeshBuilder& mb, const DistractorSpec& s) {
  const double span = s.span_m, length = s.length_ratio * span;
  const Eigen::Vector4f body = rgba(s.colour), accent = rgba(s.accent_colour);
  const double radius = 0.055 * length;
  // Fuselage: a cylinder from the tail cone to the nose, the nose a narrower cylinder.
  mb.cylinder(along_x({0, 0, 0}), radius, -0.55 * length, 0.38 * length, kRoundSegments, body, 0);
  mb.cylinder(along_x({0, 0, 0}), 0.6 * radius, 0.38 * length, 0.45 * length, kRoundSegments, body, 0);
  // Wings, from the fuselage's side, slightly ahead of the middle.
  const double c_root = 0.17 * span, c_tip = 0.06 * span, half = 0.5 * span - radius;
  for (int side : {1, -1})
    wing(mb, side, 0.05 * length, 0.8 * radius, half, c_root, c_tip, 0.12 * span, 0.012 * span, s.wing_angle_deg * kDeg,
         accent);
  // Tailplane and fin at the tail.
  const double tail_x = -0.47 * length;
  for (int side : {1, -1})
    wing(mb, side, tail_x, 0.5 * radius, 0.17 * span, 0.09 * span, 0.04 * span, 0.04 * span, 0.008 * span, 0.0, accent);
  fin(mb, -0.55 * length, 0.5 * radius, 0.14 * span, 0.11 * span, 0.05 * span, 0.07 * span, 0.008 * span, accent);
}

void build_bird(detail::MeshBuilder& mb, const DistractorSpec& s) {
  const double span = s.span_m, length = s.length_ratio * span;
  const Eigen::Vector4f body = rgba(s.colour), accent = rgba(s.accent_colour);
  const double radius = 0.09 * length + 0.015 * span;
  // Body from the tail's root to the neck, then the head and a short beak.
  mb.cylinder(along_x({0, 0, 0}), radius, -0.3 * length, 0.3 * length, kRoundSegments, body, 0);
  mb.cylinder(along_x({0, 0, 0.2 * radius}), 0.6 * radius, 0.3 * length, 0.48 * length, kRoundSegments, body, 0);
  mb.cylinder(along_x({0, 0, 0.2 * radius}), 0.2 * radius, 0.48 * length, 0.56 * length, 6, rgba(s.accent_colour, 0.5),
              0);
  // A fan tail behind the body (a flat plate widening backwards).
  mb.prism(Eigen::Isometry3d::Identity(),
           {{-0.3 * length, -0.5 * radius},
            {-0.3 * length, 0.5 * radius},
            {-0.55 * length, 1.6 * radius},
            {-0.55 * length, -1.6 * radius}},
           -0.15 * radius, 0.15 * radius, accent, 0);
  // Wings hinged at the body's side, tapered, swept back at the tips, raised by the wing beat.
  const double c_root = 0.22 * span, c_tip = 0.09 * span, half = 0.5 * span - 0.8 * radius;
  for (int side : {1, -1})
    wing(mb, side, 0.05 * length, 0.8 * radius, half, c_root, c_tip, 0.1 * span, 0.02 * span, s.wing_angle_deg * kDeg,
         accent);
}

void build_helicopter(detail::MeshBuilder& mb, std::vector<Propeller>& propellers, const DistractorSpec& s) {
  const double rotor = s.span_m, length = s.length_ratio * rotor;
  const Eigen::Vector4f body = rgba(s.colour), accent = rgba(s.accent_colour);
  // Cabin below the rotor, a little ahead of it; the tail boom to the fin and tail rotor.
  const double cabin_half_len = 0.17 * length, cabin_half_w = 0.07 * length, cabin_half_h = 0.08 * length;
  const double cabin_z = -0.09 * length - cabin_half_h;
  mb.box(Eigen::Isometry3d(Eigen::Translation3d(0.1 * length, 0, cabin_z)),
         {cabin_half_len, cabin_half_w, cabin_half_h}, body, 0);
  const double boom_end = -0.62 * length;
  mb.cylinder(along_x({0, 0, cabin_z + 0.4 * cabin_half_h}), 0.02 * length, boom_end, -0.05 * length, kRoundSegments,
              body, 0);
  fin(mb, boom_end - 0.02 * length, cabin_z + 0.3 * cabin_half_h, 0.12 * length, 0.07 * length, 0.04 * length,
      0.03 * length, 0.01 * length, accent);
  // Tail rotor: a thin disc on the boom's left side.
  Eigen::Isometry3d T_tail = Eigen::Isometry3d::Identity();
  T_tail.linear() << 1, 0, 0, 0, 0, 1, 0, -1, 0;  // own z -> body y
  T_tail.translation() = Eigen::Vector3d(boom_end + 0.03 * length, 0.0, cabin_z + 0.9 * cabin_half_h);
  mb.cylinder(T_tail, 0.08 * rotor, 0.02 * length, 0.025 * length, 16, rgba(s.accent_colour, 0.7), 0);
  // Skids: two tubes under the cabin on short struts.
  const double skid_z = cabin_z - cabin_half_h - 0.05 * length, skid_y = 1.3 * cabin_half_w;
  for (int side : {1, -1}) {
    mb.cylinder(along_x({0, side * skid_y, skid_z}), 0.008 * length, -0.1 * length, 0.32 * length, 6, accent, 0);
    const double cabin_bottom = cabin_z - cabin_half_h;
    for (double x : {0.0, 0.2 * length})
      mb.box(Eigen::Isometry3d(
                 Eigen::Translation3d(x, side * 0.5 * (skid_y + cabin_half_w), 0.5 * (skid_z + cabin_bottom))),
             {0.006 * length, 0.5 * (skid_y - cabin_half_w) + 0.006 * length, 0.5 * (cabin_bottom - skid_z)}, accent,
             0);
  }
  // Mast, then the main rotor's two blades: propeller 0, about the body z axis through the origin.
  mb.cylinder(Eigen::Isometry3d::Identity(), 0.015 * length, cabin_z + cabin_half_h, 0.0, 8, accent, 0);
  const double chord = 0.035 * rotor, t = 0.006 * rotor;
  for (int blade : {1, -1})
    mb.box(Eigen::Isometry3d(Eigen::Translation3d(0, blade * 0.25 * rotor, 0)), {0.5 * chord, 0.25 * rotor, 0.5 * t},
           accent, 1);
  propellers.push_back(Propeller{Eigen::Vector2d::Zero(), 1});
}

}  // namespace

const char* distractor_name(DistractorKind kind) {
  const int k = static_cast<int>(kind);
  return k >= 1 && k <= 3 ? common::kDetectionClassNames[k] : "unknown";
}

std::vector<std::string> DistractorSpec::validate() const {
  using common::problem;
  std::vector<std::string> p;
  const int k = static_cast<int>(kind);
  if (k < 1 || k > 3) p.push_back(problem("distractor.kind", k, "must be 1 (airplane), 2 (bird) or 3 (helicopter)"));
  if (!(span_m > 0.0 && span_m <= 100.0)) p.push_back(problem("distractor.span_m", span_m, "must be in (0, 100]"));
  if (!(length_ratio >= 0.2 && length_ratio <= 3.0))
    p.push_back(problem("distractor.length_ratio", length_ratio, "must be in [0.2, 3]"));
  if (!(wing_angle_deg >= -70.0 && wing_angle_deg <= 70.0))
    p.push_back(problem("distractor.wing_angle_deg", wing_angle_deg, "must be in [-70, 70] degrees"));
  detail::check_colour_key("distractor.colour", colour, p);
  detail::check_colour_key("distractor.accent_colour", accent_colour, p);
  return p;
}

DroneModel distractor_model(const DistractorSpec& spec) {
  const std::vector<std::string> problems = spec.validate();
  if (!problems.empty()) {
    std::string msg = "invalid distractor spec: ";
    for (size_t i = 0; i < problems.size(); ++i) msg += (i ? "; " : "") + problems[i];
    throw std::invalid_argument(msg);
  }
  detail::MeshBuilder mb;
  std::vector<Propeller> propellers;
  switch (spec.kind) {
    case DistractorKind::kAirplane:
      build_airplane(mb, spec);
      break;
    case DistractorKind::kBird:
      build_bird(mb, spec);
      break;
    case DistractorKind::kHelicopter:
      build_helicopter(mb, propellers, spec);
      break;
  }
  return mb.build(std::move(propellers), distractor_name(spec.kind));
}

}  // namespace wingman::sim
