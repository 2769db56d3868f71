#pragma once
// Helpers for the log tests: scratch files and crafted log lines.
#include <string>

namespace sdpslam::test {

// A scratch directory removed (with its files) on destruction.
class ScratchDir {
 public:
  explicit ScratchDir(const std::string& tag);
  ~ScratchDir();
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  const std::string& path() const { return path_; }
  // Writes `contents` to path()/name (gzip-compressed when `gzip`); returns the full path.
  std::string write(const std::string& name, const std::string& contents, bool gzip = false) const;

 private:
  std::string path_;
};

std::string read_file(const std::string& path);

// "FLASER n r r ... x y th ox oy oth ipc host logger" with every range = `range`.
std::string flaser_line(int n, const std::string& range, const std::string& pose, const std::string& stamp);
// A tinySLAM line: stamp, ticks, 682 ranges all `range_mm` (plus the trailing field).
std::string tinyslam_line(long long stamp_us, long long left, long long right, int range_mm);

}  // namespace sdpslam::test
