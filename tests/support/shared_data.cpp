#include "shared_data.h"

#include <ftw.h>
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

namespace {

// Directories made by make_temp_dir, removed when the test program exits normally
// (kept when SDPSLAM_KEEP_TEST_DIRS is set, to inspect a failure). Fixed storage, so
// registering one never allocates inside a test that counts allocations.
constexpr int kMaxTempDirs = 128;
char g_temp_dirs[kMaxTempDirs][512];
int g_temp_dir_count = 0;

int remove_entry(const char* path, const struct stat*, int, struct FTW*) { return ::remove(path); }

void remove_temp_dirs() {
  if (std::getenv("SDPSLAM_KEEP_TEST_DIRS") != nullptr) return;
  for (int i = 0; i < g_temp_dir_count; ++i) {
    ::nftw(g_temp_dirs[i], remove_entry, 16, FTW_DEPTH | FTW_PHYS);
  }
}

}  // namespace

std::string make_temp_dir(const std::string& tag) {
  const char* tmp = std::getenv("TMPDIR");
  std::string templ = std::string(tmp != nullptr ? tmp : "/tmp") + "/sdpslam-" + tag + "-XXXXXX";
  char buf[512];
  std::snprintf(buf, sizeof buf, "%s", templ.c_str());
  char* dir = ::mkdtemp(buf);
  if (dir == nullptr) return std::string();
  if (g_temp_dir_count == 0) std::atexit(remove_temp_dirs);
  if (g_temp_dir_count < kMaxTempDirs) {
    std::snprintf(g_temp_dirs[g_temp_dir_count++], sizeof g_temp_dirs[0], "%s", dir);
  }
  return std::string(dir);
}

}  // namespace sdpslam::test
