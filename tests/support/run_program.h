#pragma once
// Runs a command line through the shell, for the tests that drive the programs
// (sdpslam, sdpslamd) as a user would.
#include <string>

namespace sdpslam::test {

struct ProgramRun {
  int status = -1;   // exit status; -1 when the program did not exit normally
  std::string out;   // stdout and stderr together
};

// `command` runs with `2>&1` appended.
ProgramRun run_program(const std::string& command);

}  // namespace sdpslam::test
