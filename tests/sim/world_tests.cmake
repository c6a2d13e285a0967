# SPDX-License-Identifier: MIT
# Tests of the simulator's world: dynamics, scenarios and scripts, the Simulator (no rendering), and the process.

# Library: multirotor dynamics, setpoint frames, scenario files and scripted motions, the Simulator without images.
wingman_add_test(test_sim_world
  SOURCES test_multirotor.cpp test_scenario.cpp test_simulator.cpp
  LIBS wingman::sim_world wingman::test_support)

# The camera.* keys the simulator shares with the localizer (geometry::CameraModelOptions): read alike.
wingman_add_test(test_sim_camera_options
  SOURCES test_sim_camera_options.cpp
  LIBS wingman::sim_world wingman::localizer wingman::geometry wingman::common)

# The simulated autopilot's MAVLink rules (autopilot: mavlink): PX4 OFFBOARD, ArduPilot GUIDED, TIMESYNC, telemetry.
wingman_add_test(test_sim_mavlink_vehicle
  SOURCES test_mavlink_vehicle.cpp
  LIBS wingman::sim_world)

# wingman-sim as a process: file to file, lockstep on the bus of a private network namespace, errors.
wingman_add_test(test_sim_process
  SOURCES test_sim_process.cpp
  LIBS wingman::sim_world wingman::test_support wingman::lcmtypes
  LABEL netns
  TIMEOUT 180
  NETNS)
add_dependencies(test_sim_process wingman-sim wingman-localizer)

# Several cameras on the camera vehicle (cameras.rig), rendered for real (llvmpipe): images, boxes, detections per
# camera, a rig's first camera equal to the single camera, renderers sharing one GL context, bad rig files.
if(WINGMAN_BUILD_RENDER_TESTS)
  wingman_add_test(test_sim_rig
    SOURCES test_sim_rig.cpp
    LIBS wingman::sim_world wingman::test_support opencv_core opencv_imgproc
    LABEL sim
    TIMEOUT 180)
endif()
