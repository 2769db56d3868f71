// A build without ROS 2 bag support (tools/io/CMakeLists.txt: libsqlite3 or Fast-CDR was
// not found): bags are recognised and refused with what to install.
#include "ros2_bag_source.h"
#include "sdpslam/io/bags.h"

namespace sdpslam::io {
namespace {
const char* const kWhy =
    "this sdpslam was built without ROS 2 bag support (Debian: libsqlite3-dev libfastcdr-dev, then configure again)";
}  // namespace

bool ros2_bags_supported() { return false; }

struct Ros2BagWriter::Impl {};
Ros2BagWriter::Ros2BagWriter() = default;
Ros2BagWriter::~Ros2BagWriter() = default;
bool Ros2BagWriter::open(const std::string& folder, std::string* error) {
  *error = folder + ": " + kWhy;
  return false;
}
void Ros2BagWriter::odom(const OdomRecord&) {}
bool Ros2BagWriter::laser(const LaserRecord&, std::string*) { return false; }
std::uint64_t Ros2BagWriter::scans_written() const { return 0U; }
std::uint64_t Ros2BagWriter::scans_without_odometry() const { return 0U; }
bool Ros2BagWriter::close(std::string* error) {
  *error = kWhy;
  return false;
}

namespace detail {
struct Ros2BagSource::Impl {};
Ros2BagSource::Ros2BagSource() = default;
Ros2BagSource::~Ros2BagSource() = default;
bool Ros2BagSource::open(const std::string& path, const LogReaderOptions&, std::string* error) {
  *error = path + ": a ROS 2 bag, and " + kWhy;
  return false;
}
BagSource::Got Ros2BagSource::next(LaserRecord*, std::string*, bool*, std::int64_t*) { return Got::kEnd; }
}  // namespace detail

}  // namespace sdpslam::io
