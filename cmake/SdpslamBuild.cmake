# Shared build settings: warnings as errors everywhere, -Wconversion in core/.

add_library(sdpslam_warnings INTERFACE)
target_compile_options(sdpslam_warnings INTERFACE -Wall -Wextra -Werror -Wshadow -Wnon-virtual-dtor)

add_library(sdpslam_core_warnings INTERFACE)
target_link_libraries(sdpslam_core_warnings INTERFACE sdpslam_warnings)
target_compile_options(sdpslam_core_warnings INTERFACE -Wconversion -Wsign-conversion -Wdouble-promotion)

# Bit-identical results on every architecture: no fused multiply-add contraction. GCC
# contracts a*b+c into one FMA instruction by default in C++ even with -std=c++17 (its
# ISO-mode exception is for C only), and aarch64 always has FMA, so without this the
# arm64 packages compute different last bits than amd64.
add_compile_options(-ffp-contract=off)

if(SDPSLAM_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-sanitize-recover=all -fno-omit-frame-pointer)
  add_link_options(-fsanitize=address,undefined)
endif()

# sdpslam_add_test(NAME <name> SOURCES <src...> [LIBS <lib...>] [LABELS <label...>]
#                  [NEEDS_SHARED] [NO_SANITIZE] [REALTIME])
# Builds one CppUTest executable (with the common main in tests/support) and registers
# it with CTest. Under a cross build CTest runs it through CMAKE_CROSSCOMPILING_EMULATOR.
# NEEDS_SHARED: the test reads ../shared; when that folder is absent the test prints
#   why and exits 77, which CTest reports as skipped.
# NO_SANITIZE: the test replaces malloc (allocation counting) and cannot run under ASan.
# REALTIME: the test drives threads against the wall clock (ptys, sockets, players);
#   it runs alone (RUN_SERIAL), so the suite's own CPU-bound tests cannot starve it, and
#   carries the label `realtime` (see sdpslam_realtime_test()).
function(sdpslam_add_test)
  cmake_parse_arguments(T "NEEDS_SHARED;NO_SANITIZE;REALTIME" "NAME;TIMEOUT" "SOURCES;LIBS;LABELS" ${ARGN})
  # tests/ is also entered for fuzzers (fuzz preset: SDPSLAM_BUILD_TESTS=OFF), where the
  # CppUTest support and allocation-counter targets do not exist.
  if(NOT SDPSLAM_BUILD_TESTS)
    return()
  endif()
  if(T_NO_SANITIZE AND SDPSLAM_SANITIZE)
    return()
  endif()
  # A suite whose project libraries are not part of this build (e.g. host tools in a
  # cross build) is left out rather than failing the configure.
  foreach(lib IN LISTS T_LIBS)
    if(lib MATCHES "^sdpslam_" AND NOT TARGET ${lib})
      message(STATUS "${T_NAME}: not built (${lib} is not part of this build)")
      return()
    endif()
  endforeach()
  add_executable(${T_NAME} ${T_SOURCES})
  target_link_libraries(${T_NAME} PRIVATE sdpslam_test_support ${T_LIBS} sdpslam_warnings)
  add_test(NAME ${T_NAME} COMMAND ${T_NAME} -c)
  set(labels ${T_LABELS})
  if(T_NEEDS_SHARED)
    list(APPEND labels shared-data)
  endif()
  set_tests_properties(${T_NAME} PROPERTIES
    SKIP_RETURN_CODE 77
    ENVIRONMENT "SDPSLAM_SHARED_DIR=${SDPSLAM_SHARED_DIR}"
    LABELS "${labels}")
  if(T_TIMEOUT)
    set_tests_properties(${T_NAME} PROPERTIES TIMEOUT ${T_TIMEOUT})
  endif()
  if(T_REALTIME)
    sdpslam_realtime_test(${T_NAME})
  endif()
endfunction()

# sdpslam_realtime_test(<test>...): the tests run one at a time with nothing else from
# the suite beside them (on a 2-core machine two sanitizer-built filter tests leave a
# real-time thread waiting for 100 ms and more) and gain the label `realtime`
# (`ctest -L realtime` runs just them).
function(sdpslam_realtime_test)
  foreach(t IN LISTS ARGN)
    get_test_property(${t} LABELS labels)
    if(NOT labels)
      set(labels "")
    endif()
    list(APPEND labels realtime)
    set_tests_properties(${t} PROPERTIES RUN_SERIAL TRUE LABELS "${labels}")
  endforeach()
endfunction()

# sdpslam_add_fuzzer(NAME <name> SOURCES <src...> [LIBS <lib...>] [SECONDS <n>] [CORPUS <dir>])
# A libFuzzer target (clang, SDPSLAM_FUZZ=ON), registered with CTest to run for a bounded
# time (default 20 s); any crash, leak or sanitizer report fails the test. CORPUS is a
# seed folder that is copied to a scratch folder before the run, so the source tree is
# never written to.
function(sdpslam_add_fuzzer)
  if(NOT SDPSLAM_FUZZ)
    return()
  endif()
  cmake_parse_arguments(F "" "NAME;SECONDS;CORPUS" "SOURCES;LIBS" ${ARGN})
  if(NOT F_SECONDS)
    set(F_SECONDS 20)
  endif()
  foreach(lib IN LISTS F_LIBS)
    if(lib MATCHES "^sdpslam_" AND NOT TARGET ${lib})
      message(STATUS "${F_NAME}: not built (${lib} is not part of this build)")
      return()
    endif()
  endforeach()
  add_executable(${F_NAME} ${F_SOURCES})
  target_link_libraries(${F_NAME} PRIVATE ${F_LIBS} sdpslam_warnings)
  target_link_options(${F_NAME} PRIVATE -fsanitize=fuzzer)
  target_include_directories(${F_NAME} PRIVATE ${PROJECT_SOURCE_DIR}/tests/support)
  set(work "${CMAKE_CURRENT_BINARY_DIR}/${F_NAME}-corpus")
  set(seed_arg "")
  if(F_CORPUS)
    set(seed_arg "${F_CORPUS}")
  endif()
  add_test(NAME ${F_NAME}
    COMMAND ${CMAKE_COMMAND} -E env ${CMAKE_COMMAND} -DFUZZER=$<TARGET_FILE:${F_NAME}>
      -DWORK=${work} -DSEED=${seed_arg} -DSECONDS=${F_SECONDS}
      -P ${PROJECT_SOURCE_DIR}/cmake/RunFuzzer.cmake)
  set_tests_properties(${F_NAME} PROPERTIES LABELS fuzz TIMEOUT 600)
endfunction()
