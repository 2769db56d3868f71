#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>

#include "bag_common.h"
#include "sdpslam/io/log_reader.h"

namespace sdpslam::io {

detail::BagSourceMaker detail::g_make_ros1_source = nullptr;
detail::BagSourceMaker detail::g_make_ros2_source = nullptr;

bool detail::looks_like_rosbag(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  char magic[13] = {};
  f.read(magic, sizeof magic);
  return f.gcount() == static_cast<std::streamsize>(sizeof magic) &&
         std::string(magic, sizeof magic) == "#ROSBAG V2.0\n";
}

bool detail::looks_like_ros2_bag(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    if (fs::exists(fs::path(path) / "metadata.yaml", ec)) return true;
    for (const auto& e : fs::directory_iterator(path, ec)) {
      if (e.path().extension() == ".db3") return true;
    }
    return false;
  }
  std::ifstream f(path, std::ios::binary);
  char magic[16] = {};
  f.read(magic, sizeof magic);
  return f.gcount() == static_cast<std::streamsize>(sizeof magic) && std::memcmp(magic, "SQLite format 3", 16) == 0;
}

const char* to_string(LogFormat f) {
  switch (f) {
    case LogFormat::kAuto: return "auto";
    case LogFormat::kCarmen: return "carmen";
    case LogFormat::kTinySlam: return "tinyslam";
    case LogFormat::kDpSlam: return "dpslam";
    case LogFormat::kRosBag: return "rosbag";
    case LogFormat::kRos2Bag: return "ros2bag";
  }
  return "unknown";
}

std::string LogError::to_string() const { return file + ":" + std::to_string(line) + ": " + reason; }

void write_log_errors(std::FILE* out, const std::vector<LogError>& errors, std::size_t total, std::size_t max_each) {
  std::size_t shown_errors = 0U;
  std::size_t shown_warnings = 0U;
  for (const LogError& e : errors) {
    std::size_t& shown = e.warning ? shown_warnings : shown_errors;
    if (shown >= max_each) continue;
    ++shown;
    std::fprintf(out, "%s\n", e.to_string().c_str());
  }
  const std::size_t shown = shown_errors + shown_warnings;
  if (total > shown) std::fprintf(out, "... and %zu more skipped lines\n", total - shown);
}

}  // namespace sdpslam::io
