// A build without ROS 2 bag support (tools/bags/CMakeLists.txt: libsqlite3 or Fast-CDR was
// not found): bags are recognised and refused with what to install.
#include "ros2_bag_source.h"

namespace sdpslam::io::detail {
namespace {

const char* const kWhy =
    "this sdpslam was built without ROS 2 bag support (Debian: libsqlite3-dev libfastcdr-dev, then configure again)";

class RefusingWriter final : public BagWriter {
 public:
  bool open(const std::string& folder, std::string* error) override {
    *error = folder + ": " + kWhy;
    return false;
  }
  void odom(const OdomRecord&) override {}
  bool laser(const LaserRecord&, std::string*) override { return false; }
  std::uint64_t scans_written() const override { return 0U; }
  std::uint64_t scans_without_odometry() const override { return 0U; }
  bool close(std::string* error) override {
    *error = kWhy;
    return false;
  }
};

}  // namespace

std::unique_ptr<BagWriter> make_ros2_writer() { return std::make_unique<RefusingWriter>(); }
bool ros2_bags_built() { return false; }

struct Ros2BagSource::Impl {};
Ros2BagSource::Ros2BagSource() = default;
Ros2BagSource::~Ros2BagSource() = default;
bool Ros2BagSource::open(const std::string& path, const LogReaderOptions&, std::string* error) {
  *error = path + ": a ROS 2 bag, and " + kWhy;
  return false;
}
BagSource::Got Ros2BagSource::next(LaserRecord*, std::string*, bool*, std::int64_t*) { return Got::kEnd; }

}  // namespace sdpslam::io::detail
