// SPDX-License-Identifier: MIT
// What a simulated drone looks like: a procedural multirotor (quad, hex, octo) or a mesh file, with sizes and colours.
#pragma once

#include <string>
#include <vector>

namespace wingman::sim {

/// The look of one simulated drone, read from YAML through visit() (keys relative to `prefix`, e.g.
/// "drone.arm_length_m"). Geometry is in the body frame FLU (x forward, y left, z up), metres, origin at the centre
/// of the body. Colours are display (sRGB) values, three numbers in 0..1 (or all three in 0..255).
///
/// The defaults are an F450-like quad (motor axes 0.23 m from the centre on the diagonals, 0.2295 m propellers,
/// white front and red rear arms, black motors, white props) whose bounding radius with spinning propellers is
/// 0.348 m, the localizer's default target radius (target.radius_m).
struct DroneSpec {
  /// quad (4 arms, X layout), hex (6), octo (8), or mesh (mesh_path, loaded with assimp).
  std::string frame = "quad";

  // ---- procedural multirotor ----
  double arm_length_m = 0.23;       ///< motor axis distance from the body centre, metres
  double arm_width_m = 0.022;       ///< arm cross-section width (and height), metres
  double body_size_m = 0.14;        ///< centre plate width/length (x and y), metres
  double body_height_m = 0.06;      ///< centre body height, metres (centred on z = 0)
  double motor_radius_m = 0.014;    ///< motor can radius, metres
  double motor_height_m = 0.03;     ///< motor can height above the arm top, metres
  double prop_diameter_m = 0.2295;  ///< propeller tip-to-tip diameter, metres
  double prop_chord_m = 0.02;       ///< blade width, metres
  double prop_thickness_m = 0.003;  ///< blade (or disc) thickness, metres
  int prop_blades = 2;              ///< blades per propeller, 2..6
  /// blades: solid blades that spin with DroneInstance::prop_angle_rad (they blur into discs with motion blur);
  /// disc: a translucent disc (prop_thickness_m thick) per propeller, what a spinning propeller looks like at
  /// ordinary shutter speeds.
  std::string prop_style = "blades";
  double prop_disc_alpha = 0.35;  ///< opacity of a prop_style disc seen through both faces, (0, 1]
  double gear_height_m = 0.12;    ///< landing gear: how far the skids reach below the body bottom, metres (0: none)
  double gear_width_m = 0.2;      ///< landing gear: distance between the two skids (along y), metres
  double gear_length_m = 0.18;    ///< landing gear: skid length (along x), metres
  double gear_tube_m = 0.008;     ///< landing gear tube width, metres
  std::vector<double> body_colour = {0.15, 0.15, 0.15};    ///< body, sRGB
  std::vector<double> front_arm_colour = {0.9, 0.9, 0.9};  ///< arms pointing forward (x > 0), sRGB
  std::vector<double> rear_arm_colour = {0.8, 0.1, 0.1};   ///< arms pointing backward (x <= 0), sRGB
  std::vector<double> motor_colour = {0.05, 0.05, 0.05};   ///< motors, sRGB
  std::vector<double> prop_colour = {0.92, 0.92, 0.92};    ///< propellers, sRGB
  std::vector<double> gear_colour = {0.1, 0.1, 0.1};       ///< landing gear, sRGB

  // ---- mesh ----
  std::string mesh_path;    ///< frame = mesh: a file assimp reads (.glb, .gltf, .obj, .dae, .stl, ...)
  double mesh_scale = 1.0;  ///< mesh units to metres (e.g. 0.001 for millimetres)
  /// Rotation from the mesh's axes to the FLU body frame, roll, pitch, yaw in degrees (R = Rz(yaw) Ry(pitch) Rx(roll),
  /// applied after mesh_scale): e.g. {90, 0, 0} for a glTF +Y-up model whose front is +X.
  std::vector<double> mesh_rpy_deg = {0.0, 0.0, 0.0};
  /// Propellers: a mesh whose assimp node name (or else mesh name) matches this case-insensitive ECMAScript
  /// regular expression belongs to a propeller, and the matched text names it (meshes with the same matched text,
  /// e.g. "prop_0" in "prop_0_link/prop_0_first" and ".../prop_0_second", form one propeller). Each propeller spins
  /// about the body z axis through the mean of its vertices (its hub), unless mesh_prop_axes_m says where.
  /// "" = no propellers.
  std::string mesh_prop_pattern = "prop_?[0-9]+|rotor_[0-9]+";
  /// Spin axes of the mesh's propellers, body frame (x1, y1, x2, y2, ...) in metres, in the order of the
  /// propellers' names; empty = estimated from the vertices.
  std::vector<double> mesh_prop_axes_m;

  template <class V>
  void visit(V& v, const std::string& prefix = "drone.") {
    v(prefix + "frame", frame, "quad, hex, octo (procedural) or mesh (mesh_path)");
    v(prefix + "arm_length_m", arm_length_m, "motor axis distance from the body centre, metres");
    v(prefix + "arm_width_m", arm_width_m, "arm width and height, metres");
    v(prefix + "body_size_m", body_size_m, "centre body width and length, metres");
    v(prefix + "body_height_m", body_height_m, "centre body height, metres");
    v(prefix + "motor_radius_m", motor_radius_m, "motor radius, metres");
    v(prefix + "motor_height_m", motor_height_m, "motor height above the arm, metres");
    v(prefix + "prop_diameter_m", prop_diameter_m, "propeller diameter, metres");
    v(prefix + "prop_chord_m", prop_chord_m, "propeller blade width, metres");
    v(prefix + "prop_thickness_m", prop_thickness_m, "propeller blade or disc thickness, metres");
    v(prefix + "prop_blades", prop_blades, "blades per propeller, 2..6");
    v(prefix + "prop_style", prop_style, "blades (spin with the prop angle) or disc (translucent disc)");
    v(prefix + "prop_disc_alpha", prop_disc_alpha, "prop_style disc: opacity 0..1");
    v(prefix + "gear_height_m", gear_height_m, "landing gear height below the body, metres (0 = none)");
    v(prefix + "gear_width_m", gear_width_m, "distance between the skids, metres");
    v(prefix + "gear_length_m", gear_length_m, "skid length, metres");
    v(prefix + "gear_tube_m", gear_tube_m, "landing gear tube width, metres");
    v(prefix + "body_colour", body_colour, "body colour, sRGB [r, g, b] in 0..1 or 0..255");
    v(prefix + "front_arm_colour", front_arm_colour, "front arms colour, sRGB");
    v(prefix + "rear_arm_colour", rear_arm_colour, "rear arms colour, sRGB");
    v(prefix + "motor_colour", motor_colour, "motor colour, sRGB");
    v(prefix + "prop_colour", prop_colour, "propeller colour, sRGB");
    v(prefix + "gear_colour", gear_colour, "landing gear colour, sRGB");
    v(prefix + "mesh_path", mesh_path, "frame mesh: mesh file read with assimp (.glb, .obj, .dae, .stl, ...)");
    v(prefix + "mesh_scale", mesh_scale, "frame mesh: mesh units to metres");
    v(prefix + "mesh_rpy_deg", mesh_rpy_deg, "frame mesh: mesh axes to FLU body frame, [roll, pitch, yaw] degrees");
    v(prefix + "mesh_prop_pattern", mesh_prop_pattern,
      "frame mesh: regex whose match in a node/mesh name names its propeller (spins about body z)");
    v(prefix + "mesh_prop_axes_m", mesh_prop_axes_m,
      "frame mesh: propeller spin axes [x1, y1, x2, y2, ...] in metres, by propeller name ([] = estimated)");
  }

  /// Every problem, as "<prefix>key = value: rule" (empty when valid).
  std::vector<std::string> validate(const std::string& prefix = "drone.") const;

  /// Number of arms (motors) of a procedural frame: 4, 6, 8; 0 for mesh.
  int arm_count() const;
};

}  // namespace wingman::sim
