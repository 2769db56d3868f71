# Install rules, the exported CMake package and the Debian packages (CPack).
#
# Included once from the top-level CMakeLists.txt after every target exists: install()
# of a target made in another folder is allowed since CMake 3.13, and keeping the rules
# here gives one place that says what ships.
#
# Two components, one Debian package each:
#   runtime -> `sdpslam`        sdpslamd, its systemd unit, /etc/sdpslamd/sdpslamd.ini
#                               (conffile), sysusers/tmpfiles snippets, the `sdpslam` tools
#   dev     -> `libsdpslam-dev` headers, static libraries, CMake package (sdpslam::core, ...)
#
# Libraries are installed static only. The core is meant to be linked into firmware (one
# self-contained program per robot computer) and the project makes no ABI promise yet, so
# a shared library would add a soname policy and nothing else.
include(GNUInstallDirs)
include(CMakePackageConfigHelpers)

# Where the CMake package goes (relative to the prefix); follows CMAKE_INSTALL_LIBDIR
# (lib/<triplet> in the packages) unless set on the command line.
if(NOT DEFINED SDPSLAM_INSTALL_CMAKEDIR)
  set(SDPSLAM_INSTALL_CMAKEDIR "${CMAKE_INSTALL_LIBDIR}/cmake/sdpslam")
endif()

# ---- libraries, headers, CMake package (component dev) --------------------------------
# target -> name under sdpslam:: ; only what this build has (drivers and io are optional).
set(_sdpslam_exports
  sdpslam_core=core sdpslam_hal=hal
  sdpslam_drivers_common=drivers_common sdpslam_drivers_can=drivers_can
  sdpslam_drivers_serial=drivers_serial sdpslam_drivers=drivers
  sdpslam_io=io)
set(_sdpslam_export_targets "")
foreach(pair IN LISTS _sdpslam_exports)
  string(REPLACE "=" ";" pair "${pair}")
  list(GET pair 0 target)
  list(GET pair 1 export_name)
  if(TARGET ${target})
    set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
    list(APPEND _sdpslam_export_targets ${target})
  endif()
endforeach()
# The core's headers hold inline arithmetic (Pose2, det_math): users compile it without
# FMA contraction too, so their results match the library's on every architecture.
set_property(TARGET sdpslam_core APPEND PROPERTY INTERFACE_COMPILE_OPTIONS
  "$<INSTALL_INTERFACE:-ffp-contract=off>")
set(SDPSLAM_EXPORTS_IO OFF)
if(TARGET sdpslam_io)
  set(SDPSLAM_EXPORTS_IO ON)
endif()

install(TARGETS ${_sdpslam_export_targets} EXPORT sdpslamTargets
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT dev)

# Public headers: every include/ folder of an exported library (include/sdpslam/<part>/).
foreach(target IN LISTS _sdpslam_export_targets)
  get_target_property(dirs ${target} INTERFACE_INCLUDE_DIRECTORIES)
  foreach(dir IN LISTS dirs)
    if(dir MATCHES "^\\$<BUILD_INTERFACE:(.*)>$")
      install(DIRECTORY "${CMAKE_MATCH_1}/" DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        COMPONENT dev FILES_MATCHING PATTERN "*.h")
    endif()
  endforeach()
endforeach()

install(EXPORT sdpslamTargets NAMESPACE sdpslam:: DESTINATION ${SDPSLAM_INSTALL_CMAKEDIR}
  COMPONENT dev)
configure_package_config_file("${CMAKE_CURRENT_LIST_DIR}/sdpslamConfig.cmake.in"
  "${PROJECT_BINARY_DIR}/sdpslamConfig.cmake" INSTALL_DESTINATION ${SDPSLAM_INSTALL_CMAKEDIR})
write_basic_package_version_file("${PROJECT_BINARY_DIR}/sdpslamConfigVersion.cmake"
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES "${PROJECT_BINARY_DIR}/sdpslamConfig.cmake" "${PROJECT_BINARY_DIR}/sdpslamConfigVersion.cmake"
  DESTINATION ${SDPSLAM_INSTALL_CMAKEDIR} COMPONENT dev)

# ---- programs, service, configuration (component runtime) -----------------------------
# /etc when installing for the system (prefix /usr, as the packages do); under any other
# prefix the configuration stays inside it so `cmake --install --prefix DIR` never writes
# outside DIR.
if(IS_ABSOLUTE "${CMAKE_INSTALL_FULL_SYSCONFDIR}" AND NOT CMAKE_INSTALL_FULL_SYSCONFDIR MATCHES "^${CMAKE_INSTALL_PREFIX}/")
  set(SDPSLAM_INSTALL_CONFDIR "${CMAKE_INSTALL_FULL_SYSCONFDIR}/sdpslamd")
else()
  set(SDPSLAM_INSTALL_CONFDIR "${CMAKE_INSTALL_SYSCONFDIR}/sdpslamd")
endif()
# systemd's own folders under the prefix (/usr/lib/... on a merged-/usr Debian).
set(SDPSLAM_INSTALL_SYSTEMDDIR "lib/systemd/system")

if(TARGET sdpslam)
  install(TARGETS sdpslam RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  # Its ROS bag plugin (tools/bags/CMakeLists.txt), found through its $ORIGIN run path.
  install(TARGETS sdpslam_bags LIBRARY DESTINATION ${SDPSLAM_BAG_PLUGIN_INSTALL_DIR} COMPONENT runtime)
endif()
set(_sdpslam_conffiles "")
set(_sdpslam_has_daemon OFF)
if(TARGET sdpslamd)
  # Paths follow the unit (firmware-host/systemd/sdpslamd.service): ConfigurationDirectory=
  # sdpslamd, i.e. /etc/sdpslamd/sdpslamd.ini, a conffile so dpkg keeps local edits.
  set(_sdpslam_has_daemon ON)
  set(_fw "${PROJECT_SOURCE_DIR}/firmware-host")
  install(TARGETS sdpslamd RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT runtime)
  file(GLOB _units "${_fw}/systemd/*.service" "${_fw}/systemd/*.socket" "${_fw}/systemd/*.timer")
  if(_units)
    install(FILES ${_units} DESTINATION ${SDPSLAM_INSTALL_SYSTEMDDIR} COMPONENT runtime)
  endif()
  if(EXISTS "${_fw}/sdpslamd.ini")
    install(FILES "${_fw}/sdpslamd.ini" DESTINATION ${SDPSLAM_INSTALL_CONFDIR} COMPONENT runtime)
    # The unit's Documentation= points at this copy, which stays pristine.
    install(FILES "${_fw}/sdpslamd.ini" DESTINATION ${CMAKE_INSTALL_DOCDIR} COMPONENT runtime)
    if(IS_ABSOLUTE "${SDPSLAM_INSTALL_CONFDIR}")
      list(APPEND _sdpslam_conffiles "${SDPSLAM_INSTALL_CONFDIR}/sdpslamd.ini")
    else()
      list(APPEND _sdpslam_conffiles "${CMAKE_INSTALL_PREFIX}/${SDPSLAM_INSTALL_CONFDIR}/sdpslamd.ini")
    endif()
  endif()
  # The service user and the state folder (applied by the postinst, see cmake/debian/).
  foreach(kind sysusers tmpfiles)
    if(EXISTS "${_fw}/systemd/sdpslamd.${kind}.conf")
      install(FILES "${_fw}/systemd/sdpslamd.${kind}.conf" DESTINATION lib/${kind}.d
        RENAME sdpslamd.conf COMPONENT runtime)
    endif()
  endforeach()
endif()
# The offline runner's documented defaults, as an example for `sdpslam run --config`.
if(TARGET sdpslam AND EXISTS "${PROJECT_SOURCE_DIR}/firmware-host/runtime/slam/default.ini")
  install(FILES "${PROJECT_SOURCE_DIR}/firmware-host/runtime/slam/default.ini" DESTINATION ${CMAKE_INSTALL_DOCDIR}/examples
    RENAME sdpslam-run.ini COMPONENT runtime)
endif()

# ---- Debian packages ------------------------------------------------------------------
# Debian architecture of the *target* (CPack would ask dpkg, i.e. the build machine).
if(CMAKE_SYSTEM_PROCESSOR MATCHES "^(x86_64|AMD64|amd64)$")
  set(SDPSLAM_DEB_ARCH amd64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^(aarch64|arm64)$")
  set(SDPSLAM_DEB_ARCH arm64)
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^arm")
  set(SDPSLAM_DEB_ARCH armhf)  # the toolchain is arm-linux-gnueabihf
elseif(CMAKE_SYSTEM_PROCESSOR MATCHES "^i.86$")
  set(SDPSLAM_DEB_ARCH i386)
else()
  set(SDPSLAM_DEB_ARCH ${CMAKE_SYSTEM_PROCESSOR})
endif()

set(SDPSLAM_DEB_MAINTAINER "sdpslam maintainers <sdpslam@localhost>" CACHE STRING
  "Maintainer field of the Debian packages")

# Each package's Debian changelog and the programs' manual pages, compressed as Debian
# wants them (gzip -9n: no name or time stamp, so the packages are reproducible).
function(sdpslam_gzip_doc source output)
  get_filename_component(_dir "${output}" DIRECTORY)
  file(MAKE_DIRECTORY "${_dir}")
  execute_process(COMMAND gzip -9nc "${source}" OUTPUT_FILE "${output}" RESULT_VARIABLE _rc)
  if(NOT _rc EQUAL 0)
    message(FATAL_ERROR "gzip -9n ${source} failed (${_rc})")
  endif()
  set_property(DIRECTORY "${PROJECT_SOURCE_DIR}" APPEND PROPERTY CMAKE_CONFIGURE_DEPENDS "${source}")
endfunction()
set(_sdpslam_docs "${PROJECT_BINARY_DIR}/debian-doc")
configure_file("${CMAKE_CURRENT_LIST_DIR}/debian/changelog.in" "${_sdpslam_docs}/changelog.Debian" @ONLY)
sdpslam_gzip_doc("${_sdpslam_docs}/changelog.Debian" "${_sdpslam_docs}/changelog.Debian.gz")
install(FILES "${_sdpslam_docs}/changelog.Debian.gz" DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/libsdpslam-dev
  COMPONENT dev)
if(TARGET sdpslam OR TARGET sdpslamd)
  install(FILES "${_sdpslam_docs}/changelog.Debian.gz" DESTINATION ${CMAKE_INSTALL_DATAROOTDIR}/doc/sdpslam
    COMPONENT runtime)
endif()
if(TARGET sdpslam)
  sdpslam_gzip_doc("${CMAKE_CURRENT_LIST_DIR}/man/sdpslam.1" "${_sdpslam_docs}/sdpslam.1.gz")
  install(FILES "${_sdpslam_docs}/sdpslam.1.gz" DESTINATION ${CMAKE_INSTALL_MANDIR}/man1 COMPONENT runtime)
endif()
if(TARGET sdpslamd)
  sdpslam_gzip_doc("${CMAKE_CURRENT_LIST_DIR}/man/sdpslamd.8" "${_sdpslam_docs}/sdpslamd.8.gz")
  install(FILES "${_sdpslam_docs}/sdpslamd.8.gz" DESTINATION ${CMAKE_INSTALL_MANDIR}/man8 COMPONENT runtime)
endif()

set(CPACK_GENERATOR DEB)
set(CPACK_PACKAGE_NAME sdpslam)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_CONTACT "${SDPSLAM_DEB_MAINTAINER}")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY "Segmented DP-SLAM for wheeled robots in fixed memory")
set(CPACK_PACKAGING_INSTALL_PREFIX "${CMAKE_INSTALL_PREFIX}")
set(CPACK_PACKAGE_DIRECTORY "${PROJECT_BINARY_DIR}/packages")
set(CPACK_STRIP_FILES ON)
set(CPACK_DEB_COMPONENT_INSTALL ON)
set(CPACK_COMPONENTS_ALL dev)
if(TARGET sdpslam OR TARGET sdpslamd)
  list(PREPEND CPACK_COMPONENTS_ALL runtime)
endif()
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_RELEASE 1)
set(CPACK_DEBIAN_PACKAGE_ARCHITECTURE ${SDPSLAM_DEB_ARCH})
set(CPACK_DEBIAN_PACKAGE_PRIORITY optional)

set(CPACK_DEBIAN_RUNTIME_PACKAGE_NAME sdpslam)
set(CPACK_DEBIAN_RUNTIME_PACKAGE_SECTION science)
# First line: the synopsis; the rest: the long description (CPack indents it).
set(CPACK_DEBIAN_RUNTIME_DESCRIPTION "Segmented DP-SLAM onboard program and tools
sdpslamd builds a map and the robot's trajectory on the robot's computer
from wheel encoders (SocketCAN) and a laser rangefinder (serial port), in
fixed memory. The sdpslam command simulates, converts logs, runs SLAM
offline and evaluates. The systemd unit sdpslamd.service is installed but
not enabled.")
set(CPACK_DEBIAN_DEV_PACKAGE_NAME libsdpslam-dev)
set(CPACK_DEBIAN_DEV_PACKAGE_SECTION libdevel)
set(CPACK_DEBIAN_DEV_DESCRIPTION "Segmented DP-SLAM library: headers, static libraries, CMake package
find_package(sdpslam CONFIG REQUIRED) gives sdpslam::core, sdpslam::hal,
sdpslam::drivers and sdpslam::io. The libraries are static: the core is
linked into the robot's firmware.")
# The CMake package finds these (sdpslamConfig.cmake); the core needs nothing.
if(SDPSLAM_EXPORTS_IO)
  set(CPACK_DEBIAN_DEV_PACKAGE_DEPENDS "libpng-dev, libyaml-cpp-dev, nlohmann-json3-dev, zlib1g-dev")
endif()

# Depends of the programs. Natively dpkg-shlibdeps computes them from the binaries. A
# cross build cannot run it usefully (the target's libraries are not registered with the
# build machine's dpkg), so the list is stated; the packaging test checks it against the
# binaries' DT_NEEDED entries and against what dpkg-shlibdeps finds for amd64.
set(SDPSLAM_DEB_CROSS_DEPENDS
  "libc6 (>= 2.35), libgcc-s1 (>= 3.0), libinih1 (>= 40), libpng16-16 (>= 1.6.2-1), libstdc++6 (>= 11), libyaml-cpp0.7 (>= 0.7.0), zlib1g (>= 1:1.2.6)"
  CACHE STRING "Depends of the sdpslam package in cross builds (dpkg-shlibdeps is used natively)")
if(CMAKE_CROSSCOMPILING)
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_DEPENDS "${SDPSLAM_DEB_CROSS_DEPENDS}")
else()
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_SHLIBDEPS ON)
endif()

if(_sdpslam_has_daemon)
  set(_extra "${PROJECT_BINARY_DIR}/debian-runtime")
  file(MAKE_DIRECTORY "${_extra}")
  file(COPY "${CMAKE_CURRENT_LIST_DIR}/debian/postinst" "${CMAKE_CURRENT_LIST_DIR}/debian/prerm"
    "${CMAKE_CURRENT_LIST_DIR}/debian/postrm" DESTINATION "${_extra}")
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA "${_extra}/postinst;${_extra}/prerm;${_extra}/postrm")
  if(_sdpslam_conffiles)
    list(JOIN _sdpslam_conffiles "\n" _lines)
    file(WRITE "${_extra}/conffiles" "${_lines}\n")
    list(APPEND CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_EXTRA "${_extra}/conffiles")
  endif()
  set(CPACK_DEBIAN_RUNTIME_PACKAGE_CONTROL_STRICT_PERMISSION ON)
endif()

include(CPack)
