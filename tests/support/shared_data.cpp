#include "shared_data.h"

#include <sys/stat.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

namespace sdpslam::test {

std::string find_shared(const std::string& relative) {
  const char* env = std::getenv("SDPSLAM_SHARED_DIR");
  std::string base = (env != nullptr && env[0] != '\0') ? env : "../shared";
  std::string path = base + "/" + relative;
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? path : std::string();
}

std::string shared_path(const std::string& relative) {
  std::string p = find_shared(relative);
  if (p.empty()) {
    std::fprintf(stderr,
                 "SKIP: '%s' not found: the shared data folder (../shared beside the checkout, or "
                 "$SDPSLAM_SHARED_DIR) is absent; this test needs it.\n",
                 relative.c_str());
    std::fflush(stderr);
    std::_Exit(77);
  }
  return p;
}

std::string make_temp_dir(const std::string& tag) {
  const char* tmp = std::getenv("TMPDIR");
  std::string templ = std::string(tmp != nullptr ? tmp : "/tmp") + "/sdpslam-" + tag + "-XXXXXX";
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s", templ.c_str());
  char* dir = ::mkdtemp(buf);
  return dir != nullptr ? std::string(dir) : std::string();
}

}  // namespace sdpslam::test
