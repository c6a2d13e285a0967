# SPDX-License-Identifier: MIT
# Tests of wingman::sim_render: drone models and meshes, truth boxes, the renderer against its truth boxes,
# determinism (also across llvmpipe thread counts, through the wingman-render-dump helper).
add_executable(wingman-render-dump ${CMAKE_CURRENT_SOURCE_DIR}/test_render_dump_main.cpp)
set_target_properties(wingman-render-dump PROPERTIES RUNTIME_OUTPUT_DIRECTORY ${CMAKE_BINARY_DIR}/tests)
target_link_libraries(wingman-render-dump PRIVATE wingman::sim_render opencv_core opencv_imgcodecs)
wingman_warnings(wingman-render-dump)

wingman_add_test(test_sim_render
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_drone_model.cpp ${CMAKE_CURRENT_SOURCE_DIR}/test_distractor_model.cpp
          ${CMAKE_CURRENT_SOURCE_DIR}/test_render_options.cpp
          ${CMAKE_CURRENT_SOURCE_DIR}/test_render_truth_box.cpp ${CMAKE_CURRENT_SOURCE_DIR}/test_render.cpp
          ${CMAKE_CURRENT_SOURCE_DIR}/test_render_determinism.cpp
  LIBS wingman::sim_render wingman::localizer wingman::test_support opencv_core opencv_imgproc fmt::fmt
  LABEL sim
  TIMEOUT 120)
target_include_directories(test_sim_render PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
target_compile_definitions(test_sim_render PRIVATE WINGMAN_RENDER_DUMP_EXE="$<TARGET_FILE:wingman-render-dump>")
add_dependencies(test_sim_render wingman-render-dump)

# `wingman dataset synth` (tools library), read back with the trainer's dataset reader.
wingman_add_test(test_sim_dataset_synth
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_render_dataset_synth.cpp
  LIBS wingman::tools wingman::sim_render wingman::training_data wingman::test_support nlohmann_json::nlohmann_json
       opencv_imgcodecs
  LABEL sim
  TIMEOUT 120)
target_include_directories(test_sim_dataset_synth PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
target_compile_definitions(test_sim_dataset_synth PRIVATE WINGMAN_EXE="$<TARGET_FILE:wingman>")
add_dependencies(test_sim_dataset_synth wingman)

# `wingman dataset from-log`: flight logs (real LCM log files) to a YOLO dataset, read back with the trainer's reader.
wingman_add_test(test_sim_dataset_from_log
  SOURCES ${CMAKE_CURRENT_SOURCE_DIR}/test_dataset_from_log.cpp
  LIBS wingman::tools wingman::training_data wingman::test_support opencv_imgcodecs
  LABEL sim
  TIMEOUT 60)
target_compile_definitions(test_sim_dataset_from_log PRIVATE WINGMAN_EXE="$<TARGET_FILE:wingman>")
add_dependencies(test_sim_dataset_from_log wingman)
