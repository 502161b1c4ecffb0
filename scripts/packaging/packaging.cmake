# Debian packages (issue 61), built by CPack's DEB generator from any preset's build directory:
#   cmake --preset release|aarch64|armhf -B DIR && cmake --build DIR --target mmlfw [tools...]
#   (cd DIR && cpack -G DEB)        # or scripts/packaging/build_debs.sh, scripts/bench.sh deploy
# mmlfw        the firmware binary, its man page, the CAN DBC, the systemd unit, the example config
#              /etc/mmlfw/mmlfw.conf (a conffile), the maps folder /var/lib/mmlfw/maps; every preset
#              (amd64 from release, arm64 from aarch64, armhf from armhf).
# mmlfw-tools  the host tools (map compiler and builder, AntSLAM, simulator, evaluation, CARMEN and
#              the CAN/SICK device models), man pages made from their --help; host builds only.
# Version from the tree: 0.0.<commits>+g<hash> (git), the Debian architecture from the toolchain,
# Depends from dpkg-shlibdeps run at packaging time (shlibdeps.cmake; cross builds read the cross
# libc's shlibs files under /usr/<triplet>/lib).
set(_pkg ${CMAKE_CURRENT_LIST_DIR})

# --- version from the tree ------------------------------------------------------------------------
# An exported tree (git archive, no .git) gets its version from the caller:
# -DMMLFW_PACKAGE_VERSION_OVERRIDE=0.0.N+gHASH -DMMLFW_PACKAGE_DATE_OVERRIDE="<RFC 2822 date>".
set(MMLFW_PACKAGE_VERSION_OVERRIDE "" CACHE STRING "package version (default: from git)")
set(MMLFW_PACKAGE_DATE_OVERRIDE "" CACHE STRING "changelog date (default: the HEAD commit's)")
set(MMLFW_PACKAGE_VERSION "0.0.0")
find_package(Git QUIET)
if(MMLFW_PACKAGE_VERSION_OVERRIDE)
  set(MMLFW_PACKAGE_VERSION "${MMLFW_PACKAGE_VERSION_OVERRIDE}")
  set(_date "${MMLFW_PACKAGE_DATE_OVERRIDE}")
elseif(GIT_FOUND)
  execute_process(COMMAND ${GIT_EXECUTABLE} rev-list --count HEAD WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                  OUTPUT_VARIABLE _count OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE _r1)
  execute_process(COMMAND ${GIT_EXECUTABLE} rev-parse --short=9 HEAD WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                  OUTPUT_VARIABLE _hash OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET RESULT_VARIABLE _r2)
  execute_process(COMMAND ${GIT_EXECUTABLE} log -1 --format=%cD WORKING_DIRECTORY ${PROJECT_SOURCE_DIR}
                  OUTPUT_VARIABLE _date OUTPUT_STRIP_TRAILING_WHITESPACE ERROR_QUIET)
  if(_r1 EQUAL 0 AND _r2 EQUAL 0)
    set(MMLFW_PACKAGE_VERSION "0.0.${_count}+g${_hash}")
  endif()
endif()
if(NOT _date)
  set(_date "Thu, 01 Jan 1970 00:00:00 +0000")
endif()

# --- Debian architecture ----------------------------------------------------------------------------
if(MMLFW_CROSS_TRIPLET STREQUAL "aarch64-linux-gnu")
  set(MMLFW_DEB_ARCH arm64)
elseif(MMLFW_CROSS_TRIPLET STREQUAL "arm-linux-gnueabihf")
  set(MMLFW_DEB_ARCH armhf)
else()
  execute_process(COMMAND dpkg --print-architecture OUTPUT_VARIABLE MMLFW_DEB_ARCH OUTPUT_STRIP_TRAILING_WHITESPACE
                  ERROR_QUIET)
  if(NOT MMLFW_DEB_ARCH)
    set(MMLFW_DEB_ARCH amd64)
  endif()
endif()

# --- files generated for both packages (changelog, copyright) ----------------------------------------
set(_gen ${CMAKE_BINARY_DIR}/packaging)
file(MAKE_DIRECTORY ${_gen})
foreach(_p mmlfw mmlfw-tools)
  # A native package (no Debian revision): its changelog is changelog.gz.
  file(WRITE ${_gen}/${_p}/changelog
       "${_p} (${MMLFW_PACKAGE_VERSION}) unstable; urgency=medium\n\n"
       "  * Built from the mmlfw tree at ${MMLFW_PACKAGE_VERSION} (git commit count and hash).\n\n"
       " -- mmlfw developers <mmlfw@mmlfw.invalid>  ${_date}\n")
  execute_process(COMMAND gzip -9nf ${_gen}/${_p}/changelog)
endforeach()
execute_process(COMMAND gzip -9nc ${_pkg}/mmlfw.1 OUTPUT_FILE ${_gen}/mmlfw.1.gz)

# --- mmlfw -------------------------------------------------------------------------------------------
# Full RELRO for the packaged binaries (lintian's hardening-no-bindnow; Debian's default flags).
target_link_options(mmlfw PRIVATE -Wl,-z,relro,-z,now)
install(TARGETS mmlfw RUNTIME DESTINATION bin COMPONENT mmlfw)
install(FILES ${_gen}/mmlfw.1.gz DESTINATION share/man/man1 COMPONENT mmlfw)
install(FILES ${PROJECT_SOURCE_DIR}/hal/can/mmlfw.dbc DESTINATION share/mmlfw COMPONENT mmlfw)
install(FILES ${_pkg}/copyright ${_gen}/mmlfw/changelog.gz DESTINATION share/doc/mmlfw COMPONENT mmlfw)
# Absolute destinations outside the prefix (/usr): the conffile, the unit, the maps folder.
install(FILES ${_pkg}/mmlfw.conf DESTINATION /etc/mmlfw COMPONENT mmlfw)
install(FILES ${_pkg}/mmlfw.service DESTINATION /lib/systemd/system COMPONENT mmlfw)
install(DIRECTORY DESTINATION /var/lib/mmlfw/maps COMPONENT mmlfw)
set(_components mmlfw)

# --- mmlfw-tools (host builds) ------------------------------------------------------------------------
set(MMLFW_PACKAGED_TOOLS mml-mapc mml-mapbuild mml-slam mml-sim mml-eval mml-carmen mml-candev mml-sickdev)
set(_summary_mml-mapc "compile a ROS map into the mmlfw map image")
set(_summary_mml-mapbuild "build a global map from a corrected laser log")
set(_summary_mml-slam "AntSLAM, build a map from a raw CARMEN log")
set(_summary_mml-sim "run the mmlfw localizer in a simulated robot")
set(_summary_mml-eval "evaluate the localizers on logs and generated runs")
set(_summary_mml-carmen "inspect, convert and score CARMEN logs")
set(_summary_mml-candev "replay a CARMEN log as mmlfw CAN traffic")
set(_summary_mml-sickdev "replay a CARMEN log as SICK LMS2xx telegrams")
set(_tools)
if(MMLFW_BUILD_HOST_TOOLS AND NOT CMAKE_CROSSCOMPILING)
  foreach(_t IN LISTS MMLFW_PACKAGED_TOOLS)
    if(TARGET ${_t})
      list(APPEND _tools ${_t})
      target_link_options(${_t} PRIVATE -Wl,-z,relro,-z,now)
      install(TARGETS ${_t} RUNTIME DESTINATION bin COMPONENT tools)
      # A man page made from the tool's own --help at install time (help2man style, plain text).
      install(CODE "execute_process(COMMAND ${_pkg}/help2roff.sh $<TARGET_FILE:${_t}> ${_t} \"${MMLFW_PACKAGE_VERSION}\"
                      \"\$ENV{DESTDIR}\${CMAKE_INSTALL_PREFIX}/share/man/man1/${_t}.1.gz\" \"${_summary_${_t}}\"
                      RESULT_VARIABLE _r)
                    if(_r EQUAL 3)
                      message(WARNING \"${_t} has no working --help: packaged without a man page\")
                    elseif(NOT _r EQUAL 0)
                      message(FATAL_ERROR \"man page of ${_t}: help2roff.sh failed (\${_r})\")
                    endif()" COMPONENT tools)
    endif()
  endforeach()
  install(FILES ${_pkg}/copyright ${_gen}/mmlfw-tools/changelog.gz DESTINATION share/doc/mmlfw-tools
          COMPONENT tools)
  list(APPEND _components tools)
endif()

# --- CPack ---------------------------------------------------------------------------------------------
set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME mmlfw)
set(CPACK_PACKAGE_VERSION ${MMLFW_PACKAGE_VERSION})
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_PACKAGE_CONTACT "mmlfw developers <mmlfw@mmlfw.invalid>")
set(CPACK_DEBIAN_PACKAGE_MAINTAINER "mmlfw developers <mmlfw@mmlfw.invalid>")
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${MMLFW_DEB_ARCH})
set(CPACK_DEBIAN_PACKAGE_SECTION misc)
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_COMPRESSION_TYPE xz)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL ${_components})
set(CPACK_COMPONENTS_GROUPING IGNORE)
set(CPACK_STRIP_FILES ON)
# dpkg's own parents (/etc, /lib, /var, /var/lib) are not owned by the package.
set(CPACK_DEBIAN_PACKAGE_GENERATE_SHLIBS OFF)
set(CPACK_DEBIAN_MMLFW_PACKAGE_NAME mmlfw)
set(CPACK_DEBIAN_MMLFW_DESCRIPTION "onboard global localization (MML) for mobile robots
mmlfw finds a robot's pose in a known building map from a 2-D laser scanner
and wheel odometry, with no initial guess (MML: RBSM scan matching, pRANSAM
map matching and MML's localization constraints), says when it is sure, and
then tracks the pose with an integrity monitor and a protection level.
.
This package holds the firmware binary, a systemd unit (Type=notify, with a
watchdog), an example configuration and the CAN message set (DBC).")
set(CPACK_DEBIAN_MMLFW_PACKAGE_CONTROL_EXTRA
    "${_pkg}/debian/conffiles;${_pkg}/debian/postinst;${_pkg}/debian/prerm;${_pkg}/debian/postrm")
set(CPACK_DEBIAN_MMLFW_PACKAGE_CONTROL_STRICT_PERMISSION ON)
set(CPACK_DEBIAN_TOOLS_PACKAGE_NAME mmlfw-tools)
set(CPACK_DEBIAN_TOOLS_DESCRIPTION "host tools for mmlfw: map compiler, map builder, simulator
The host side of mmlfw: mml-mapc compiles a ROS map into the firmware's map
image, mml-mapbuild builds a map from a corrected log, mml-slam (AntSLAM)
from a raw log, mml-sim runs the firmware in a simulated robot, mml-eval
evaluates it, mml-carmen reads CARMEN logs, and mml-candev / mml-sickdev
replay logs as CAN traffic or SICK telegrams.")
# Depends: dpkg-shlibdeps on the packaged binaries when cpack runs (shlibdeps.cmake).
set(CPACK_PROJECT_CONFIG_FILE ${CMAKE_BINARY_DIR}/packaging/cpack_project.cmake)
set(_tool_files)
foreach(_t IN LISTS _tools)
  list(APPEND _tool_files "$<TARGET_FILE:${_t}>")
endforeach()
file(GENERATE OUTPUT ${CMAKE_BINARY_DIR}/packaging/cpack_project.cmake CONTENT
"set(MMLFW_DEB_ARCH \"${MMLFW_DEB_ARCH}\")
set(MMLFW_CROSS_TRIPLET \"${MMLFW_CROSS_TRIPLET}\")
set(MMLFW_SHLIBDEPS_mmlfw \"$<TARGET_FILE:mmlfw>\")
set(MMLFW_SHLIBDEPS_tools \"${_tool_files}\")
set(MMLFW_EXTRA_DEPENDS_mmlfw \"adduser\")
include(\"${_pkg}/shlibdeps.cmake\")
")
include(CPack)
