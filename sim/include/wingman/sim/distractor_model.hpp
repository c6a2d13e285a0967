// SPDX-License-Identifier: MIT
// What flies in the picture and is not a drone: procedural airplanes, birds and helicopters (the other classes of
// the Halmstad labels), rendered as distractors in synthetic training images.
#pragma once

#include "wingman/sim/drone_model.hpp"

#include <string>
#include <vector>

namespace wingman::sim {

/// The kinds, numbered as the detector's classes (0 is the drone): 1 airplane, 2 bird, 3 helicopter.
enum class DistractorKind : int { kAirplane = 1, kBird = 2, kHelicopter = 3 };

/// "airplane", "bird" or "helicopter": the class name of common::kDetectionClassNames ("unknown" for another value).
const char* distractor_name(DistractorKind kind);

/// One distractor's shape. The model's body frame is FLU (x forward, y left, z up), metres, with its origin at the
/// wings' root (airplane, bird) or on the main rotor's axis (helicopter).
struct DistractorSpec {
  DistractorKind kind = DistractorKind::kBird;
  /// Wing span tip to tip (airplane, bird) or main rotor diameter (helicopter), metres, in (0, 100].
  double span_m = 1.0;
  /// Fuselage or body length (helicopter: cabin to tail) over span_m, in [0.2, 3].
  double length_ratio = 0.5;
  /// The wings' angle above the horizontal, degrees in [-70, 70]: a bird's wing beat at this instant, an airplane's
  /// dihedral (the helicopter has none: ignored).
  double wing_angle_deg = 0.0;
  /// Main colour (fuselage, body) and second colour (wings, tail, rotor): sRGB, three values in 0..1 (or 0..255),
  /// as DroneSpec's colours.
  std::vector<double> colour = {0.35, 0.35, 0.35};
  std::vector<double> accent_colour = {0.2, 0.2, 0.2};

  /// Every problem as "distractor.key = value: rule"; empty when valid.
  std::vector<std::string> validate() const;
};

/// The distractor's mesh: an airplane (round fuselage, tapered swept wings, tailplane, fin), a bird (body, head, fan
/// tail, two tapered wings hinged at the body at wing_angle_deg) or a helicopter (cabin, tail boom, fin, tail rotor,
/// skids, and a two-blade main rotor that is propeller 0: it turns with DroneInstance::prop_angle_rad like a drone's
/// propeller). name() is distractor_name(kind); bounding_radius() holds the spinning rotor.
/// Throws std::invalid_argument listing validate()'s problems.
DroneModel distractor_model(const DistractorSpec& spec);

}  // namespace wingman::sim
