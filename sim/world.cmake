# SPDX-License-Identifier: MIT
# wingman::sim_world: multirotor dynamics, motion scripts, scenarios and the Simulator (testable without LCM), plus
# the wingman-sim process (thin main). Included by sim/CMakeLists.txt after render.cmake.
add_library(wingman_sim_world
  src/world/multirotor.cpp
  src/world/vehicle_command.cpp
  src/world/motion_script.cpp
  src/world/scenario.cpp
  src/world/sim_options.cpp
  src/world/sim_cameras.cpp
  src/world/simulator.cpp
  src/world/mavlink_vehicle.cpp
  src/world/own_pose_error.cpp
  src/world/truth_detections.cpp)
add_library(wingman::sim_world ALIAS wingman_sim_world)
target_include_directories(wingman_sim_world PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>)
target_link_libraries(wingman_sim_world
  PUBLIC wingman::sim_render wingman::geometry wingman::common wingman::mavlink wingman::lcmtypes Eigen3::Eigen opencv_core
         wingman::camera_driver  # PreviewOptions (the monitoring preview of the rendered camera)
  PRIVATE yaml-cpp fmt::fmt)
wingman_warnings(wingman_sim_world)

add_executable(wingman-sim main.cpp)
# launcher: BusWatch for sync.wait_for (the launchers' wait for heartbeats).
target_link_libraries(wingman-sim PRIVATE wingman::sim_world wingman::mavlink_bridge wingman::common wingman::launcher
                                          spdlog::spdlog fmt::fmt)
wingman_warnings(wingman-sim)
