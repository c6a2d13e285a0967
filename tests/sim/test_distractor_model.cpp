// SPDX-License-Identifier: MIT
// Distractor models (procedural airplanes, birds, helicopters): validation, their span and bounding radius, the
// bird's wing beat and the helicopter's spinning rotor.
#include <gtest/gtest.h>
#include <wingman/sim/distractor_model.hpp>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace wingman::sim {
namespace {

/// The posed points' extent along one body axis: {min, max}.
std::pair<double, double> extent(const DroneModel& m, int axis, double prop_angle_rad = 0.0) {
  std::vector<Eigen::Vector3d> points;
  m.posed_points(prop_angle_rad, points);
  double lo = 1e9, hi = -1e9;
  for (const Eigen::Vector3d& p : points) lo = std::min(lo, p[axis]), hi = std::max(hi, p[axis]);
  return {lo, hi};
}

DistractorSpec spec_of(DistractorKind kind, double span_m, double length_ratio) {
  DistractorSpec s;
  s.kind = kind;
  s.span_m = span_m;
  s.length_ratio = length_ratio;
  return s;
}

TEST(DistractorSpec, DefaultsAreValidAndValidateNamesEveryBadField) {
  EXPECT_TRUE(DistractorSpec{}.validate().empty());
  DistractorSpec s;
  s.kind = static_cast<DistractorKind>(4);
  s.span_m = -1.0;
  s.length_ratio = 5.0;
  s.wing_angle_deg = 80.0;
  s.colour = {-0.5, 0.0, 0.0};
  s.accent_colour = {0.5, 0.5};
  const std::vector<std::string> p = s.validate();
  ASSERT_EQ(p.size(), 6u);
  for (const char* key : {"distractor.kind", "distractor.span_m", "distractor.length_ratio",
                          "distractor.wing_angle_deg", "distractor.colour", "distractor.accent_colour"}) {
    EXPECT_TRUE(std::any_of(p.begin(), p.end(), [&](const std::string& q) { return q.find(key) == 0; }))
        << key << " not named";
  }
  DistractorSpec nan_span;
  nan_span.span_m = std::nan("");
  EXPECT_EQ(nan_span.validate().size(), 1u);
  try {
    (void)distractor_model(s);
    FAIL() << "an invalid spec was built";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("distractor.span_m"), std::string::npos) << e.what();
  }
}

TEST(DistractorModel, EachKindSpansItsSpanAndIsNamedForIt) {
  for (const auto& [kind, span, length] :
       std::vector<std::tuple<DistractorKind, double, double>>{{DistractorKind::kAirplane, 30.0, 0.9},
                                                               {DistractorKind::kBird, 0.8, 0.4},
                                                               {DistractorKind::kHelicopter, 11.0, 1.1}}) {
    const DroneModel m = distractor_model(spec_of(kind, span, length));
    EXPECT_EQ(m.name(), distractor_name(kind));
    EXPECT_GT(m.triangle_count(), 20u);
    // Wing tips (the rotor along y at angle 0) reach +-span / 2 within a few per cent.
    const auto [y_min, y_max] = extent(m, 1);
    EXPECT_NEAR(y_max, 0.5 * span, 0.04 * span) << distractor_name(kind);
    EXPECT_NEAR(y_min, -0.5 * span, 0.04 * span) << distractor_name(kind);
    // Nose to tail: about length_ratio x span.
    const auto [x_min, x_max] = extent(m, 0);
    EXPECT_GT(x_max - x_min, 0.8 * length * span) << distractor_name(kind);
    EXPECT_LT(x_max - x_min, 1.2 * length * span + 0.05 * span) << distractor_name(kind);
    // The bounding sphere holds the tips and the tail, and not much more.
    EXPECT_GE(m.bounding_radius(), 0.5 * span - 0.04 * span);
    EXPECT_LE(m.bounding_radius(), 0.75 * std::max(1.0, length) * span);
  }
}

TEST(DistractorModel, BirdWingsBeatAboutTheirRoots) {
  DistractorSpec s = spec_of(DistractorKind::kBird, 1.0, 0.4);
  const DroneModel level = distractor_model(s);
  s.wing_angle_deg = 45.0;
  const DroneModel up = distractor_model(s);
  s.wing_angle_deg = -45.0;
  const DroneModel down = distractor_model(s);
  // Level: the body's height; raised: the tips about (span / 2) sin 45 deg above, lowered: as far below.
  EXPECT_LT(extent(level, 2).second, 0.1);
  EXPECT_NEAR(extent(up, 2).second, 0.5 * std::sin(M_PI / 4), 0.06);
  EXPECT_NEAR(extent(down, 2).first, -0.5 * std::sin(M_PI / 4), 0.06);
  EXPECT_LT(extent(up, 1).second, 0.5 * std::cos(M_PI / 4) + 0.06);  // the span seen from above shrinks
  EXPECT_TRUE(level.propellers().empty());
}

TEST(DistractorModel, HelicopterRotorIsOnePropellerThatSpinsAboutTheMast) {
  const double rotor = 10.0;
  const DroneModel m = distractor_model(spec_of(DistractorKind::kHelicopter, rotor, 1.0));
  ASSERT_EQ(m.propellers().size(), 1u);
  EXPECT_EQ(m.propellers()[0].axis_in_body, Eigen::Vector2d::Zero());
  // The blades lie along y at angle 0 and along x a quarter turn later; the spinning rotor is in the radius.
  EXPECT_NEAR(extent(m, 1, 0.0).second, 0.5 * rotor, 0.02 * rotor);
  EXPECT_LT(extent(m, 1, M_PI / 2).second, 0.2 * rotor);
  EXPECT_NEAR(extent(m, 0, M_PI / 2).second, 0.5 * rotor, 0.02 * rotor);
  EXPECT_GE(m.bounding_radius(), 0.5 * rotor);
  // The tail reaches behind the rotor disc.
  EXPECT_LT(extent(m, 0, M_PI / 2).first, -0.55 * rotor);
}

}  // namespace
}  // namespace wingman::sim
