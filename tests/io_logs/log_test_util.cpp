#include "log_test_util.h"

#include <zlib.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "shared_data.h"

namespace sdpslam::test {

ScratchDir::ScratchDir(const std::string& tag) : path_(make_temp_dir(tag)) {}

ScratchDir::~ScratchDir() {
  std::error_code ec;
  if (!path_.empty()) std::filesystem::remove_all(path_, ec);
}

std::string ScratchDir::write(const std::string& name, const std::string& contents, bool gzip) const {
  const std::string p = path_ + "/" + name;
  if (gzip) {
    gzFile f = gzopen(p.c_str(), "wb");
    if (f != nullptr) {
      gzwrite(f, contents.data(), static_cast<unsigned>(contents.size()));
      gzclose(f);
    }
  } else {
    std::ofstream out(p, std::ios::binary);
    out << contents;
  }
  return p;
}

std::string read_file(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string flaser_line(int n, const std::string& range, const std::string& pose, const std::string& stamp) {
  std::string s = "FLASER " + std::to_string(n);
  for (int i = 0; i < n; ++i) s += " " + range;
  s += " " + pose + " " + pose + " " + stamp + " nohost 0.5";
  return s;
}

std::string tinyslam_line(long long stamp_us, long long left, long long right, int range_mm) {
  std::string s = std::to_string(stamp_us) + " 14554 " + std::to_string(left) + " " + std::to_string(right);
  for (int i = 4; i < 24; ++i) s += " 0";
  for (int i = 0; i < 682; ++i) s += " " + std::to_string(range_mm);
  s += " 0";
  return s;
}

}  // namespace sdpslam::test
