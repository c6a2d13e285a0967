// SPDX-License-Identifier: MIT
// wingman-render-dump OUT_PREFIX: renders a fixed scene (default sky, ground, trees, noise; a bladed quad and a disc
// hex) without and with motion blur and writes OUT_PREFIX_plain.png and OUT_PREFIX_blur.png. The determinism test
// runs it under different LP_NUM_THREADS and compares the bytes.
#include <wingman/sim/renderer.hpp>

#include <opencv2/imgcodecs.hpp>

#include <iostream>

int main(int argc, char** argv) {
  using namespace wingman;
  if (argc != 2) {
    std::cerr << "usage: wingman-render-dump OUT_PREFIX" << std::endl;
    return 2;
  }
  try {
    const geometry::CameraModel camera(1280, 720, 820.0, 815.0, 645.3, 355.8, geometry::Distortion::kRadTan,
                                       {-0.32, 0.11, 0.0012, -0.0009, -0.015});
    sim::RenderOptions options;
    options.exposure_jitter = 0.2;
    sim::Renderer renderer(camera, options);
    const sim::DroneModel quad = sim::DroneModel::procedural(sim::DroneSpec{});
    sim::DroneSpec hex_spec;
    hex_spec.frame = "hex";
    hex_spec.prop_style = "disc";
    const sim::DroneModel hex = sim::DroneModel::procedural(hex_spec);
    Eigen::Isometry3d T_cam_to_world = Eigen::Isometry3d::Identity();
    T_cam_to_world.linear() << 1, 0, 0, 0, 0.1, 0.995, 0, -0.995, 0.1;  // looking north, tilted up a little
    T_cam_to_world.linear() = Eigen::Quaterniond(T_cam_to_world.linear()).normalized().toRotationMatrix();
    T_cam_to_world.translation() = Eigen::Vector3d(0.0, 0.0, 12.0);
    std::vector<sim::DroneInstance> drones(2);
    drones[0].vehicle_id = 1;
    drones[0].model = &quad;
    drones[0]
        .T_body_to_world.translate(Eigen::Vector3d(-1.5, 9.0, 12.5))
        .rotate(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()));
    drones[0].v_body_in_world = {4.0, 0.0, 1.0};
    drones[0].prop_angle_rad = 0.7;
    drones[0].prop_rate_rad_s = 600.0;
    drones[1].vehicle_id = 2;
    drones[1].model = &hex;
    drones[1]
        .T_body_to_world.translate(Eigen::Vector3d(2.0, 15.0, 13.0))
        .rotate(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitX()));
    drones[1].w_body_in_body = {0.0, 0.0, 2.0};
    const sim::RenderResult plain = renderer.render(T_cam_to_world, drones, 1'700'000'000'000'000, 99);
    options.motion_blur_exposure_s = 0.01;
    options.motion_blur_samples = 3;
    renderer.set_options(options);
    sim::CameraMotion motion;
    motion.v_cam_in_world = {0.0, 3.0, 0.0};
    motion.w_cam_in_cam = {0.0, 0.5, 0.0};
    const sim::RenderResult blurred = renderer.render(T_cam_to_world, drones, 1'700'000'000'033'333, 100, motion);
    const std::string prefix = argv[1];
    cv::Mat plain_out, blur_out;
    cv::merge(std::vector<cv::Mat>{plain.bgr, plain.mask}, plain_out);  // mask as a 4th channel (lossless PNG)
    cv::merge(std::vector<cv::Mat>{blurred.bgr, blurred.mask}, blur_out);
    if (!cv::imwrite(prefix + "_plain.png", plain_out) || !cv::imwrite(prefix + "_blur.png", blur_out)) {
      std::cerr << "wingman-render-dump: error: cannot write " << prefix << "_*.png" << std::endl;
      return 1;
    }
  } catch (const std::exception& e) {
    std::cerr << "wingman-render-dump: error: " << e.what() << std::endl;
    return 1;
  }
  return 0;
}
