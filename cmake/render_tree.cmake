# SPDX-License-Identifier: MIT
# tools/supervise.sh's rendering (cmake -P): config/supervisor/wingman.conf for a build tree or any other layout,
# through the same renderer as `cmake --install` (cmake/wingman_render.cmake), and with STANDALONE a supervisord.conf
# of its own (config/supervisor/supervisord.standalone.conf.in) that runs it without root.
# Input (-D): SOURCE_DIR, OUT (the rendered file), BIN, ETC, LOG_DIR (the processes' logs and the recorder's
# recordings), LCM_URL (empty: the file's), STANDALONE (empty: none; else its folder).
include("${CMAKE_CURRENT_LIST_DIR}/wingman_render.cmake")
foreach(required SOURCE_DIR OUT BIN ETC LOG_DIR)
  if(NOT DEFINED ${required} OR "${${required}}" STREQUAL "")
    message(FATAL_ERROR "render_tree.cmake: -D${required}=... is required")
  endif()
endforeach()
file(READ "${SOURCE_DIR}/config/supervisor/wingman.conf" text)
# The stopped-process listener runs from this checkout's config/supervisor (installed: share/wingman/supervisor).
wingman_render_text(text "${text}" BIN "${BIN}" ETC "${ETC}" SHARE "${SOURCE_DIR}/config" RECORDINGS_LOG "${LOG_DIR}"
                    SUPERVISOR_LOG "${LOG_DIR}" LCM_URL "${LCM_URL}")
file(WRITE "${OUT}" "${text}")
if(DEFINED STANDALONE AND NOT STANDALONE STREQUAL "")
  configure_file("${SOURCE_DIR}/config/supervisor/supervisord.standalone.conf.in" "${STANDALONE}/supervisord.conf" @ONLY)
endif()
