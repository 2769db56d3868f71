# Runs one libFuzzer binary for a bounded time on a scratch copy of its seed corpus and
# prints its closing statistics (executions, coverage). Fails on any crash or report.
# SDPSLAM_FUZZ_SECONDS in the environment overrides the per-target budget.
if(DEFINED ENV{SDPSLAM_FUZZ_SECONDS})
  set(SECONDS $ENV{SDPSLAM_FUZZ_SECONDS})
endif()
file(REMOVE_RECURSE "${WORK}")
file(MAKE_DIRECTORY "${WORK}")
if(SEED AND EXISTS "${SEED}")
  file(GLOB seeds "${SEED}/*")
  if(seeds)
    file(COPY ${seeds} DESTINATION "${WORK}")
  endif()
endif()
execute_process(
  COMMAND "${FUZZER}" -max_total_time=${SECONDS} -print_final_stats=1 -timeout=10
          -rss_limit_mb=2048 "-artifact_prefix=${WORK}/../" "${WORK}"
  RESULT_VARIABLE rc
  OUTPUT_VARIABLE out
  ERROR_VARIABLE err)
string(REGEX MATCHALL "(stat::number_of_executed_units|stat::new_units_added|cov: [0-9]+ ft: [0-9]+)[^\n]*" stats "${err}")
message(STATUS "fuzzer ${FUZZER}: ${stats}")
if(NOT rc EQUAL 0)
  message(FATAL_ERROR "fuzzer failed (exit ${rc}):\n${err}")
endif()
