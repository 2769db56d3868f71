#pragma once
// Access to ../shared (benchmark logs, sensor captures), which lives beside the checkout
// and is never copied into the repository.
#include <string>

namespace sdpslam::test {

// Path of `relative` inside the shared folder. If the file is not there, prints a
// message naming the missing path and exits with status 77, which CTest reports as
// "skipped" for tests registered with NEEDS_SHARED.
std::string shared_path(const std::string& relative);

// Same lookup without exiting: empty string when absent.
std::string find_shared(const std::string& relative);

// A fresh, empty temporary directory for one test's outputs under $TMPDIR (or /tmp).
// It and its contents are removed when the test program exits normally, unless
// SDPSLAM_KEEP_TEST_DIRS is set in the environment.
std::string make_temp_dir(const std::string& tag);

}  // namespace sdpslam::test
