# SPDX-License-Identifier: MIT
# Install-time part of `cmake --install` (install(SCRIPT) from the top CMakeLists.txt): the process configurations,
# the supervisord program file and the systemd units, rendered for the prefix given at install time
# (`cmake --install build --prefix P`; DESTDIR honoured). The shipped files are written for /usr/local; here every
# /usr/local path in them becomes the prefix's, with the GNU directory rules (GNUInstallDirs):
#   executables   <prefix>/bin
#   configuration <prefix>/etc/wingman; /etc/wingman for the prefix /usr; /etc/opt/<name>/wingman for /opt/<name>
#   shared files  <prefix>/share/wingman (supervisor/, systemd/)
#   logs          supervisord's: /var/log/supervisor (the supervisor package's own folder); the recorder's
#                 recordings: <localstatedir>/log/wingman/recordings, created here (/var for /usr, /var/opt/<name> for
#                 /opt/<name>, <prefix>/var otherwise); systemd's units use LogsDirectory= (always /var/log/wingman).
# Input (set by install(CODE) before this script): WINGMAN_SOURCE_DIR.

if(NOT WINGMAN_SOURCE_DIR)
  message(FATAL_ERROR "install_layout.cmake: WINGMAN_SOURCE_DIR is not set")
endif()
set(prefix "${CMAKE_INSTALL_PREFIX}")
string(REGEX REPLACE "/+$" "" prefix "${prefix}")
if(prefix STREQUAL "/usr")
  set(sysconfdir "/etc")
  set(localstatedir "/var")
elseif(prefix MATCHES "^/opt/[^/]+$")
  set(sysconfdir "/etc${prefix}")
  set(localstatedir "/var${prefix}")
else()
  set(sysconfdir "${prefix}/etc")
  set(localstatedir "${prefix}/var")
endif()
set(bindir "${prefix}/bin")
set(confdir "${sysconfdir}/wingman")
set(datadir "${prefix}/share/wingman")
set(recordings "${localstatedir}/log/wingman/recordings")
set(dest "$ENV{DESTDIR}")

# The process configurations (what tests and flights run: the shipped config/*.yaml, unchanged).
foreach(name camera_driver detector localizer follower_ctrl mavlink_bridge recorder)
  file(INSTALL "${WINGMAN_SOURCE_DIR}/config/${name}.yaml" DESTINATION "${confdir}")  # DESTDIR: added by file(INSTALL)
endforeach()
# The camera rigs (several cameras on one vehicle: the localizer's and the simulator's cameras.rig), unchanged.
file(GLOB rigs "${WINGMAN_SOURCE_DIR}/config/rigs/*.yaml")
file(INSTALL ${rigs} DESTINATION "${confdir}/rigs")

# The shipped files with the prefix's paths (cmake/wingman_render.cmake, also tools/supervise.sh's renderer).
include("${CMAKE_CURRENT_LIST_DIR}/wingman_render.cmake")
function(wingman_render in out)
  file(READ "${in}" text)
  if(out MATCHES "wingman\\.conf$")
    wingman_render_text(text "${text}" BIN "${bindir}" ETC "${confdir}" SHARE "${datadir}"
                        RECORDINGS_LOG "${localstatedir}/log/wingman")
  else()
    wingman_render_text(text "${text}" BIN "${bindir}" ETC "${confdir}" SHARE "${datadir}")
  endif()
  set(mark "#")
  if(out MATCHES "\\.conf$")
    set(mark ";")
  endif()
  set(text "${mark} Rendered by `cmake --install` for the prefix ${prefix}: where the comments below say /usr/local, read\n${mark} ${prefix} (configurations: ${confdir}).\n${text}")
  get_filename_component(dir "${dest}${out}" DIRECTORY)
  file(MAKE_DIRECTORY "${dir}")
  file(WRITE "${dest}${out}" "${text}")
  message(STATUS "Installing (rendered for ${prefix}): ${dest}${out}")
endfunction()
wingman_render("${WINGMAN_SOURCE_DIR}/config/supervisor/wingman.conf" "${datadir}/supervisor/wingman.conf")
file(INSTALL "${WINGMAN_SOURCE_DIR}/config/supervisor/wingman-stopped-watch.py" DESTINATION "${datadir}/supervisor"
     FILE_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE GROUP_READ GROUP_EXECUTE WORLD_READ WORLD_EXECUTE)
file(GLOB units "${WINGMAN_SOURCE_DIR}/config/systemd/*.service" "${WINGMAN_SOURCE_DIR}/config/systemd/*.target")
foreach(unit ${units})
  get_filename_component(name "${unit}" NAME)
  wingman_render("${unit}" "${datadir}/systemd/${name}")
endforeach()

# The recorder's folder under supervisord (a missing one stops only the recorder, never supervisord).
file(MAKE_DIRECTORY "${dest}${recordings}")
message(STATUS "Installing: ${dest}${recordings}/ (the recorder's recordings under supervisord)")
