// SPDX-License-Identifier: MIT
// Drone specs and models: validation, the procedural frames, spinning propellers, bounding radii, mesh loading
// (including the assembled real airframes in ../shared/meshes).
#include "test_constants.hpp"
#include "test_render_support.hpp"

#include <gtest/gtest.h>
#include <wingman/common/config.hpp>
#include <wingman/localizer/sphere_localizer.hpp>
#include <wingman/sim/drone_model.hpp>

#include <cstring>
#include <fstream>
#include <map>
#include <regex>

namespace wingman::sim {
namespace {

using test::joined;
using wingman::testing::kPi;

/// A config file section "drone:" with a DroneSpec, as a process would read it.
struct DroneConfig {
  DroneSpec drone;
  template <class V>
  void visit(V& v) {
    drone.visit(v);
  }
  std::vector<std::string> validate() const { return drone.validate(); }
};

TEST(DroneSpec, DefaultsAreValid) {
  EXPECT_TRUE(DroneSpec{}.validate().empty()) << joined(DroneSpec{}.validate());
  EXPECT_EQ(DroneSpec{}.arm_count(), 4);
}

TEST(DroneSpec, ValidateNamesEveryBadField) {
  DroneSpec spec;
  spec.frame = "tri";
  spec.arm_length_m = -1.0;
  spec.prop_blades = 9;
  spec.prop_style = "fan";
  spec.body_colour = {1.0, 2.0};
  spec.gear_colour = {300.0, 0.0, 0.0};
  const std::string problems = joined(spec.validate());
  for (const char* key :
       {"drone.frame = 'tri'", "drone.arm_length_m = -1", "drone.prop_blades = 9", "drone.prop_style = 'fan'",
        "drone.body_colour = '[1, 2]'", "drone.gear_colour = '[300, 0, 0]'"}) {
    EXPECT_NE(problems.find(key), std::string::npos) << key << " missing from:\n" << problems;
  }
  spec = DroneSpec{};
  spec.frame = "mesh";
  const std::string mesh_problems = joined(spec.validate("target."));
  EXPECT_NE(mesh_problems.find("target.mesh_path"), std::string::npos) << mesh_problems;
}

TEST(DroneSpec, YamlLoaderReportsEveryBadKeyAtOnce) {
  const std::string yaml = "drone:\n  frame: hex\n  arm_length_m: 0.3\n  prop_colour: [255, 128, 0]\n";
  const DroneConfig ok = common::load_options_from_string<DroneConfig>(yaml, "d.yaml");
  EXPECT_EQ(ok.drone.frame, "hex");
  EXPECT_EQ(ok.drone.arm_count(), 6);
  try {
    common::load_options_from_string<DroneConfig>("drone:\n  frame: tri\n  arm_lenght_m: 0.3\n  prop_blades: x\n",
                                                  "d.yaml");
    FAIL() << "bad config accepted";
  } catch (const common::ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("drone.arm_lenght_m"), std::string::npos) << what;
    EXPECT_NE(what.find("drone.prop_blades"), std::string::npos) << what;
    EXPECT_NE(what.find("drone.frame = 'tri'"), std::string::npos) << what;
  }
}

TEST(DroneModel, DefaultQuadHasTheLocalizersDefaultRadius) {
  const DroneModel model = DroneModel::procedural(DroneSpec{});
  // F450 with spinning propellers: 0.348 m, the localizer's default target radius.
  EXPECT_NEAR(model.bounding_radius(), localizer::SphereLocalizerOptions{}.radius_m, 5e-4);
  EXPECT_NEAR(model.bounding_radius(), 0.348, 5e-4);
  EXPECT_LT(model.bounding_radius_at_rest(), model.bounding_radius());
  // Without its propellers: the farthest vertex of the rigid part (0), a plain loop.
  double frame = 0.0;
  for (const DroneVertex& v : model.vertices())
    if (v.part == 0) frame = std::max(frame, v.p_in_body.cast<double>().norm());
  EXPECT_DOUBLE_EQ(model.frame_radius(), frame);
  EXPECT_GT(model.frame_radius(), 0.2);
  EXPECT_LT(model.frame_radius(), model.bounding_radius() - 0.05) << "the propellers reach beyond the frame";
  EXPECT_EQ(model.propellers().size(), 4u);
  EXPECT_EQ(model.name(), "quad");
}

TEST(DroneModel, ProceduralFramesHaveOneCounterRotatingPropellerPerArm) {
  for (const auto& [frame, arms] : std::vector<std::pair<std::string, int>>{{"quad", 4}, {"hex", 6}, {"octo", 8}}) {
    DroneSpec spec;
    spec.frame = frame;
    spec.arm_length_m = 0.4;
    const DroneModel model = DroneModel::procedural(spec);
    ASSERT_EQ(model.propellers().size(), static_cast<size_t>(arms)) << frame;
    int sum = 0;
    for (const Propeller& p : model.propellers()) {
      EXPECT_NEAR(p.axis_in_body.norm(), 0.4, 1e-12) << frame;
      sum += p.direction;
    }
    EXPECT_EQ(sum, 0) << frame << ": as many propellers turn each way";
    EXPECT_GT(model.triangle_count(), 100u);
  }
}

TEST(DroneModel, BoundingRadiusHoldsAtEveryPropellerAngleAndIsReached) {
  for (const char* frame : {"quad", "hex"}) {
    DroneSpec spec;
    spec.frame = frame;
    spec.prop_blades = 3;
    const DroneModel model = DroneModel::procedural(spec);
    double reached = 0.0;
    std::vector<Eigen::Vector3d> points;
    for (int k = 0; k < 720; ++k) {
      model.posed_points(2.0 * kPi * k / 720, points);
      for (const Eigen::Vector3d& p : points) {
        ASSERT_LE(p.norm(), model.bounding_radius() + 1e-6) << frame << " at angle step " << k;
        reached = std::max(reached, p.norm());
      }
    }
    EXPECT_NEAR(reached, model.bounding_radius(), 2e-4) << frame;
  }
}

TEST(DroneModel, PropellersSpinAboutTheirOwnAxesAndTheBodyStaysPut) {
  const DroneModel model = DroneModel::procedural(DroneSpec{});
  std::vector<Eigen::Vector3d> rest, turned;
  model.posed_points(0.0, rest);
  model.posed_points(1.1, turned);
  ASSERT_EQ(rest.size(), turned.size());
  size_t moved = 0;
  for (size_t i = 0; i < rest.size(); ++i) {
    if ((rest[i] - turned[i]).norm() < 1e-12) continue;
    ++moved;
    // A moved point keeps its height and its distance from one of the propeller axes.
    EXPECT_NEAR(rest[i].z(), turned[i].z(), 1e-12);
    bool on_axis = false;
    for (const Propeller& p : model.propellers()) {
      const double r0 = (rest[i].head<2>() - p.axis_in_body).norm();
      const double r1 = (turned[i].head<2>() - p.axis_in_body).norm();
      on_axis = on_axis || (std::abs(r0 - r1) < 1e-6 && r0 < 0.15);
    }
    EXPECT_TRUE(on_axis) << "point " << i;
  }
  EXPECT_GT(moved, 50u);
  // Turning by direction * angle: a full turn is the identity.
  model.posed_points(2.0 * kPi, turned);
  for (size_t i = 0; i < rest.size(); ++i) EXPECT_NEAR((rest[i] - turned[i]).norm(), 0.0, 1e-9);
}

TEST(DroneModel, DiscPropellersAreTranslucentAndDrawnLast) {
  DroneSpec spec;
  spec.prop_style = "disc";
  const DroneModel model = DroneModel::procedural(spec);
  ASSERT_LT(model.opaque_index_count(), model.indices().size());
  for (size_t i = 0; i < model.indices().size(); ++i) {
    const float alpha = model.vertices()[model.indices()[i]].colour.w();
    if (i < model.opaque_index_count()) {
      EXPECT_EQ(alpha, 1.0f);
    } else {
      EXPECT_FLOAT_EQ(alpha, 1.0f - std::sqrt(1.0f - 0.35f)) << "two faces let 1 - 0.35 through";
    }
  }
}

TEST(DroneModel, ColoursGivenIn0To255AreTheSameAsIn0To1AndLinearised) {
  DroneSpec a, b;
  a.body_colour = {0.5, 0.25, 1.0};
  b.body_colour = {127.5, 63.75, 255.0};
  const DroneModel ma = DroneModel::procedural(a), mb = DroneModel::procedural(b);
  ASSERT_EQ(ma.vertices().size(), mb.vertices().size());
  EXPECT_TRUE(ma.vertices()[0].colour.isApprox(mb.vertices()[0].colour, 1e-6f));
  // sRGB 0.5 is linear 0.214.
  EXPECT_NEAR(ma.vertices()[0].colour.x(), 0.214, 1e-3);
}

TEST(DroneModel, RejectsInvalidGeometryAndSpecs) {
  DroneVertex v{Eigen::Vector3f::Zero(), Eigen::Vector3f::UnitZ(), Eigen::Vector4f::Ones(), 0};
  EXPECT_THROW(DroneModel({v, v, v}, {0, 1, 3}, 3, {}, "bad index"), std::invalid_argument);
  EXPECT_THROW(DroneModel({v, v, v}, {0, 1}, 0, {}, "not triangles"), std::invalid_argument);
  v.part = 2;
  EXPECT_THROW(DroneModel({v, v, v}, {0, 1, 2}, 3, {Propeller{}}, "bad part"), std::invalid_argument);
  DroneSpec spec;
  spec.prop_diameter_m = 0.0;
  try {
    DroneModel::procedural(spec);
    FAIL() << "invalid spec accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("drone.prop_diameter_m"), std::string::npos) << e.what();
  }
}

TEST(MeshLoader, AppliesScaleAndRotationAndFindsPropellers) {
  wingman::testing::TempDir dir;
  const std::string path = dir.file("frame.obj");
  // A unit square plate 'body' at z = 0 and a blade 'prop_1' from x = 2..4 at z = 1 (mesh units: decimetres).
  std::ofstream(path) << "o body\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3\nf 1 3 4\n"
                      << "o prop_1\nv 2 -0.1 1\nv 4 -0.1 1\nv 4 0.1 1\nv 2 0.1 1\nf 5 6 7\nf 5 7 8\n";
  DroneSpec spec;
  spec.frame = "mesh";
  spec.mesh_path = path;
  spec.mesh_scale = 0.1;
  spec.mesh_rpy_deg = {0.0, 0.0, 90.0};  // the file's +x is the drone's left (+y)
  const DroneModel model = DroneModel::from_spec(spec);
  EXPECT_EQ(model.name(), "frame.obj");
  EXPECT_EQ(model.triangle_count(), 4u);
  ASSERT_EQ(model.propellers().size(), 1u);
  EXPECT_NEAR(model.propellers()[0].axis_in_body.x(), 0.0, 1e-6);
  EXPECT_NEAR(model.propellers()[0].axis_in_body.y(), 0.3, 1e-6);
  Eigen::Vector3f lo = Eigen::Vector3f::Constant(1e9f), hi = -lo;
  for (const DroneVertex& v : model.vertices()) {
    lo = lo.cwiseMin(v.p_in_body);
    hi = hi.cwiseMax(v.p_in_body);
  }
  EXPECT_TRUE(lo.isApprox(Eigen::Vector3f(-0.1f, -0.1f, 0.0f), 1e-5f)) << lo.transpose();
  EXPECT_TRUE(hi.isApprox(Eigen::Vector3f(0.1f, 0.4f, 0.1f), 1e-5f)) << hi.transpose();
  // The blade spins about (0, 0.3): its tip corners, hypot(0.1, 0.01) from the axis, sweep out to 0.3 + that at
  // z = 0.1.
  EXPECT_NEAR(model.bounding_radius(), std::hypot(0.3 + std::hypot(0.1, 0.01), 0.1), 1e-6);
  // Axes given in the spec win over the estimate; a wrong count is an error naming the key.
  spec.mesh_prop_axes_m = {0.0, 0.25};
  EXPECT_NEAR(DroneModel::from_spec(spec).propellers()[0].axis_in_body.y(), 0.25, 1e-12);
  spec.mesh_prop_axes_m = {0.0, 0.25, 1.0, 1.0};
  try {
    DroneModel::from_spec(spec);
    FAIL() << "4 axis numbers accepted for 1 propeller";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("mesh_prop_axes_m"), std::string::npos) << e.what();
  }
}

TEST(MeshLoader, ErrorsNameTheFile) {
  wingman::testing::TempDir dir;
  DroneSpec spec;
  spec.frame = "mesh";
  spec.mesh_path = dir.file("absent.glb");
  try {
    DroneModel::from_spec(spec);
    FAIL() << "a missing file loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("absent.glb: no such mesh file"), std::string::npos) << e.what();
  }
  spec.mesh_path = dir.file("junk.stl");
  std::ofstream(spec.mesh_path) << "this is not a mesh";
  try {
    DroneModel::from_spec(spec);
    FAIL() << "junk loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("junk.stl"), std::string::npos) << e.what();
  }
}

/// The number under "key" in the JSON chunk of a binary glTF file (NaN if absent).
double glb_json_number(const std::string& path, const std::string& key) {
  std::ifstream in(path, std::ios::binary);
  char header[20];
  in.read(header, sizeof(header));
  uint32_t json_length = 0;
  std::memcpy(&json_length, header + 12, 4);
  std::string json(json_length, '\0');
  in.read(json.data(), json_length);
  std::smatch m;
  if (!std::regex_search(json, m, std::regex("\"" + key + "\"\\s*:\\s*([0-9.eE+-]+)"))) return std::nan("");
  return std::stod(m[1]);
}

TEST(MeshLoader, SharedAirframesHaveTheirStatedBoundingRadii) {
  const std::string missing = test::missing_shared("meshes");
  if (!missing.empty()) GTEST_SKIP() << "airframe meshes not available: " << missing << " is absent";
  // The meshes' README's "r without props" (the frame radius), read from its table.
  const std::map<std::string, double> r_frame = {
      {"dji_f450.glb", 0.297}, {"holybro_x500v2.glb", 0.281}, {"tarot_t650.glb", 0.367}, {"3dr_iris.glb", 0.274}};
  for (const char* name : {"dji_f450.glb", "holybro_x500v2.glb", "tarot_t650.glb", "3dr_iris.glb"}) {
    DroneSpec spec;
    spec.frame = "mesh";
    spec.mesh_path = test::shared_path(std::string("meshes/") + name);
    const DroneModel model = DroneModel::from_spec(spec);
    // The file states r_spin (asset.extras.bounding_sphere_radius_m) to 0.1 mm, and its rest-pose radius in a note.
    const double r_spin = glb_json_number(spec.mesh_path, "bounding_sphere_radius_m");
    const double prop_axis = glb_json_number(spec.mesh_path, "motor_axis_radius_m");
    ASSERT_TRUE(std::isfinite(r_spin)) << name;
    EXPECT_NEAR(model.bounding_radius(), r_spin, 1e-3) << name;
    EXPECT_NEAR(model.frame_radius(), r_frame.at(name), 1e-3) << name;
    ASSERT_EQ(model.propellers().size(), 4u) << name;
    double farthest_axis = 0.0;
    for (const Propeller& p : model.propellers()) farthest_axis = std::max(farthest_axis, p.axis_in_body.norm());
    EXPECT_NEAR(farthest_axis, prop_axis, 2e-3) << name;
    EXPECT_GT(model.triangle_count(), 10000u) << name;
  }
}

}  // namespace
}  // namespace wingman::sim
