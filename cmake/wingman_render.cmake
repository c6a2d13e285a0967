# SPDX-License-Identifier: MIT
# The one renderer of the shipped supervisor and systemd files (written for /usr/local): every installed path in
# them becomes the given layout's. Used by cmake/install_layout.cmake (`cmake --install`, any prefix) and
# cmake/render_tree.cmake (tools/supervise.sh: a build tree or any other layout).
#
# wingman_render_text(<out_var> <text> BIN <dir> ETC <dir> SHARE <dir> [RECORDINGS_LOG <dir>] [SUPERVISOR_LOG <dir>]
#                     [LCM_URL <url>])
#   /usr/local/bin/ -> BIN/, /usr/local/etc/wingman/ -> ETC/, /usr/local/share/wingman/ -> SHARE/, and when given:
#   /var/log/wingman/ -> RECORDINGS_LOG/, /var/log/supervisor/ -> SUPERVISOR_LOG/, the shipped LCM URL -> LCM_URL.
#   Plain text replacement, in that order (paths are taken literally: no character is special).
set(WINGMAN_SHIPPED_LCM_URL "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304")
function(wingman_render_text out_var text)
  cmake_parse_arguments(R "" "BIN;ETC;SHARE;RECORDINGS_LOG;SUPERVISOR_LOG;LCM_URL" "" ${ARGN})
  foreach(required BIN ETC SHARE)
    if(NOT DEFINED R_${required})
      message(FATAL_ERROR "wingman_render_text: ${required} is required")
    endif()
  endforeach()
  string(REPLACE "/usr/local/bin/" "${R_BIN}/" text "${text}")
  string(REPLACE "/usr/local/etc/wingman/" "${R_ETC}/" text "${text}")
  if(DEFINED R_RECORDINGS_LOG)
    string(REPLACE "/var/log/wingman/" "${R_RECORDINGS_LOG}/" text "${text}")
  endif()
  if(DEFINED R_SUPERVISOR_LOG)
    string(REPLACE "/var/log/supervisor/" "${R_SUPERVISOR_LOG}/" text "${text}")
  endif()
  string(REPLACE "/usr/local/share/wingman/" "${R_SHARE}/" text "${text}")
  if(DEFINED R_LCM_URL AND NOT R_LCM_URL STREQUAL "")
    string(REPLACE "${WINGMAN_SHIPPED_LCM_URL}" "${R_LCM_URL}" text "${text}")
  endif()
  set(${out_var} "${text}" PARENT_SCOPE)
endfunction()
