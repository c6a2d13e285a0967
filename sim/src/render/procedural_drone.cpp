// SPDX-License-Identifier: MIT
// DroneModel::procedural: a multirotor (quad, hex, octo in X layout) built from boxes, cylinders and blades.
#include "colour.hpp"
#include "mesh_builder.hpp"
#include "wingman/sim/drone_model.hpp"

#include <fmt/format.h>

#include <cmath>
#include <stdexcept>

namespace wingman::sim {
namespace {

constexpr int kMotorSegments = 16;
constexpr int kDiscSegments = 48;
constexpr double kHubGapM = 0.004;          // from the motor top to the blade plane, metres
constexpr double kBladePitchRad = 0.2;      // blade angle of attack (about its own radial axis)
constexpr double kTipChordFraction = 0.35;  // tip chord / root chord

Eigen::Vector4f rgba(const std::vector<double>& srgb, double alpha = 1.0) {
  const Eigen::Vector3d c = detail::linear_colour(srgb);
  return Eigen::Vector4f(static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z()),
                         static_cast<float>(alpha));
}

Eigen::Isometry3d pose(const Eigen::Vector3d& t, double yaw_rad = 0.0) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T.translation() = t;
  return T;
}

// A square tube of width `w` from p0 to p1.
void tube(detail::MeshBuilder& mb, const Eigen::Vector3d& p0, const Eigen::Vector3d& p1, double w,
          const Eigen::Vector4f& colour) {
  const Eigen::Vector3d d = p1 - p0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitX(), d).toRotationMatrix();
  T.translation() = 0.5 * (p0 + p1);
  mb.box(T, Eigen::Vector3d(0.5 * d.norm(), 0.5 * w, 0.5 * w), colour, 0);
}

}  // namespace

DroneModel DroneModel::procedural(const DroneSpec& spec) {
  std::vector<std::string> problems = spec.validate();
  if (spec.frame == "mesh") problems.push_back("drone.frame = 'mesh': procedural() needs quad, hex or octo");
  if (!problems.empty()) {
    std::string msg = "invalid drone spec: ";
    for (size_t i = 0; i < problems.size(); ++i) msg += (i ? "; " : "") + problems[i];
    throw std::invalid_argument(msg);
  }
  detail::MeshBuilder mb;
  const int n = spec.arm_count();
  const double half_body_h = 0.5 * spec.body_height_m;
  const double half_arm = 0.5 * spec.arm_width_m;

  // Body: centre box, a lid on top and a battery below.
  const Eigen::Vector4f body = rgba(spec.body_colour);
  mb.box(pose({0, 0, 0}), {0.5 * spec.body_size_m, 0.5 * spec.body_size_m, half_body_h}, body, 0);
  const Eigen::Vector4f lid(body.x() * 0.6f + 0.02f, body.y() * 0.6f + 0.02f, body.z() * 0.6f + 0.02f, 1.0f);
  mb.box(pose({0, 0, half_body_h + 0.1 * spec.body_height_m}),
         {0.35 * spec.body_size_m, 0.3 * spec.body_size_m, 0.1 * spec.body_height_m}, lid, 0);
  mb.box(pose({0, 0, -half_body_h - 0.15 * spec.body_height_m}),
         {0.4 * spec.body_size_m, 0.18 * spec.body_size_m, 0.15 * spec.body_height_m}, rgba({0.35, 0.35, 0.4}), 0);

  // Arms, motors and propellers; arm k at yaw pi/n + 2 pi k / n (X layout), propellers alternating direction.
  std::vector<Propeller> propellers;
  const double prop_radius = 0.5 * spec.prop_diameter_m;
  const double z_motor_top = half_arm + spec.motor_height_m;
  const double z_prop = z_motor_top + kHubGapM;
  const double chord = spec.prop_chord_m;
  for (int k = 0; k < n; ++k) {
    const double yaw = M_PI / n + 2.0 * M_PI * k / n;
    const Eigen::Vector3d dir(std::cos(yaw), std::sin(yaw), 0.0);
    const Eigen::Vector3d motor = spec.arm_length_m * dir;
    const bool front = dir.x() > 1e-9;
    mb.box(pose(0.5 * motor, yaw), {0.5 * spec.arm_length_m, half_arm, half_arm},
           rgba(front ? spec.front_arm_colour : spec.rear_arm_colour), 0);
    mb.cylinder(pose(motor), spec.motor_radius_m, half_arm, z_motor_top, kMotorSegments, rgba(spec.motor_colour), 0);

    const int part = k + 1;
    const int direction = k % 2 == 0 ? 1 : -1;
    propellers.push_back(Propeller{motor.head<2>(), direction});
    const Eigen::Vector4f prop = rgba(spec.prop_colour);
    mb.cylinder(pose(motor), 0.5 * spec.motor_radius_m, z_motor_top, z_prop + 0.5 * spec.prop_thickness_m,
                kMotorSegments, prop, part);
    if (spec.prop_style == "disc") {
      // A flat cylinder; each face lets 1 - a through, so that both faces together give prop_disc_alpha.
      const double face_alpha = 1.0 - std::sqrt(1.0 - spec.prop_disc_alpha);
      mb.cylinder(pose({motor.x(), motor.y(), z_prop}), prop_radius, -0.5 * spec.prop_thickness_m,
                  0.5 * spec.prop_thickness_m, kDiscSegments, rgba(spec.prop_colour, face_alpha), part);
      continue;
    }
    const double root = 0.4 * spec.motor_radius_m;
    const std::vector<Eigen::Vector2d> blade = {{root, -0.5 * chord},
                                                {prop_radius, -0.5 * kTipChordFraction * chord},
                                                {prop_radius, 0.5 * kTipChordFraction * chord},
                                                {root, 0.5 * chord}};
    for (int b = 0; b < spec.prop_blades; ++b) {
      Eigen::Isometry3d T = pose({motor.x(), motor.y(), z_prop}, 2.0 * M_PI * b / spec.prop_blades);
      T.rotate(Eigen::AngleAxisd(direction * kBladePitchRad, Eigen::Vector3d::UnitX()));
      mb.prism(T, blade, -0.5 * spec.prop_thickness_m, 0.5 * spec.prop_thickness_m, prop, part);
    }
  }

  // Landing gear: two skids along x, each held by two struts from the body's underside.
  if (spec.gear_height_m > 0.0) {
    const Eigen::Vector4f gear = rgba(spec.gear_colour);
    const double w = spec.gear_tube_m;
    const double z_skid = -half_body_h - spec.gear_height_m + 0.5 * w;
    for (double side : {-1.0, 1.0}) {
      const double y = side * 0.5 * spec.gear_width_m;
      tube(mb, {-0.5 * spec.gear_length_m, y, z_skid}, {0.5 * spec.gear_length_m, y, z_skid}, w, gear);
      for (double fore : {-1.0, 1.0}) {
        const Eigen::Vector3d top(fore * 0.3 * spec.body_size_m, side * 0.3 * spec.body_size_m, -half_body_h);
        const Eigen::Vector3d foot(fore * 0.3 * spec.gear_length_m, y, z_skid);
        tube(mb, top, foot, w, gear);
      }
    }
  }
  return mb.build(std::move(propellers), spec.frame);
}

}  // namespace wingman::sim
