# SPDX-License-Identifier: MIT
# wingman::sim_render: the simulator's camera. Drone models (procedural multirotors, meshes through assimp), exact
# truth boxes, and offscreen OpenGL ES rendering through EGL (Mesa llvmpipe; no window system).
pkg_check_modules(GLESV2 REQUIRED IMPORTED_TARGET glesv2)
pkg_check_modules(WINGMAN_EGL REQUIRED IMPORTED_TARGET egl)
find_package(assimp REQUIRED)

add_library(wingman_sim_render
  src/render/colour.cpp
  src/render/drone_spec.cpp
  src/render/drone_model.cpp
  src/render/mesh_builder.cpp
  src/render/procedural_drone.cpp
  src/render/distractor_model.cpp
  src/render/mesh_loader.cpp
  src/render/truth_box.cpp
  src/render/render_options.cpp
  src/render/egl_context.cpp
  src/render/gl_program.cpp
  src/render/lens_map.cpp
  src/render/shaders.cpp
  src/render/renderer.cpp)
add_library(wingman::sim_render ALIAS wingman_sim_render)
target_include_directories(wingman_sim_render
  PUBLIC $<BUILD_INTERFACE:${CMAKE_CURRENT_SOURCE_DIR}/include>
  PRIVATE ${CMAKE_CURRENT_SOURCE_DIR}/src/render)
target_link_libraries(wingman_sim_render
  PUBLIC wingman::geometry wingman::common Eigen3::Eigen opencv_core
  PRIVATE PkgConfig::GLESV2 PkgConfig::WINGMAN_EGL assimp::assimp fmt::fmt)
wingman_warnings(wingman_sim_render)
