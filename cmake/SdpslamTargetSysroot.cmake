# Target-architecture libraries for cross builds that cannot use Debian multiarch.
#
# The cross builds of the tools and of sdpslamd need libpng, zlib, inih and yaml-cpp for
# the target architecture. The usual way is multiarch (`apt-get install libpng-dev:arm64`),
# but that fails whenever the mirror's foreign-architecture indexes lag the host's
# (Multi-Arch: same packages such as libc6-dev must have identical versions on every
# architecture), and libyaml-cpp-dev cannot be installed beside the build machine's own
# at all (it is not Multi-Arch: same).
# cmake/fetch-target-sysroot.sh then unpacks the target's .deb files (apt-get download +
# dpkg -x) into a folder, and SDPSLAM_TARGET_SYSROOT points at it.
#
# Only the *libraries* come from that folder: the compiler keeps its own sysroot
# (/usr/<triplet> of the Debian cross toolchain) for libc and libstdc++. When the folder
# is absent or empty nothing changes, so a multiarch installation is used as before.
set(SDPSLAM_TARGET_SYSROOT "" CACHE PATH
  "Cross builds: folder with the target's -dev packages unpacked by cmake/fetch-target-sysroot.sh")

if(CMAKE_CROSSCOMPILING AND SDPSLAM_TARGET_SYSROOT)
  set(_sysroot_libdir "${SDPSLAM_TARGET_SYSROOT}/usr/lib/${CMAKE_LIBRARY_ARCHITECTURE}")
  if(IS_DIRECTORY "${_sysroot_libdir}")
    message(STATUS "Target libraries from ${SDPSLAM_TARGET_SYSROOT} (compiler sysroot unchanged)")
    # find_library/find_path/find_package look in the folder first, then in the usual
    # places (mode BOTH), so header-only host packages (CLI11, nlohmann-json) are still found.
    list(APPEND CMAKE_FIND_ROOT_PATH "${SDPSLAM_TARGET_SYSROOT}")
    # pkg-config (inih): the folder's .pc files come first, and the -I/-L paths they name
    # (/usr/...) are rewritten into the folder.
    set(ENV{PKG_CONFIG_PATH} "${_sysroot_libdir}/pkgconfig:${SDPSLAM_TARGET_SYSROOT}/usr/share/pkgconfig")
    set(ENV{PKG_CONFIG_SYSROOT_DIR} "${SDPSLAM_TARGET_SYSROOT}")
    # libpng16.so needs libz.so.1 at link time: tell the linker where the target's is
    # (zlib1g ships it in /lib/<triplet>).
    add_link_options("LINKER:-rpath-link,${_sysroot_libdir}:${SDPSLAM_TARGET_SYSROOT}/lib/${CMAKE_LIBRARY_ARCHITECTURE}")
  else()
    message(STATUS "SDPSLAM_TARGET_SYSROOT=${SDPSLAM_TARGET_SYSROOT} holds no "
      "${CMAKE_LIBRARY_ARCHITECTURE} libraries: using the multiarch installation")
  endif()
  unset(_sysroot_libdir)
endif()
