// A build without ROS 1 bag support (tools/bags/CMakeLists.txt: the ROS packages were not
// found): bags are recognised and refused with what to install.
#include "rosbag_source.h"

namespace sdpslam::io::detail {

struct RosBagSource::Impl {};

RosBagSource::RosBagSource() = default;
RosBagSource::~RosBagSource() = default;

bool RosBagSource::open(const std::string& path, const LogReaderOptions&, std::string* error) {
  *error = path + ": a ROS 1 bag, and this sdpslam was built without ROS bag support (Debian: "
                  "librosbag-storage-dev libsensor-msgs-dev libnav-msgs-dev libtf2-msgs-dev, then configure again)";
  return false;
}

RosBagSource::Got RosBagSource::next(LaserRecord*, std::string*, bool*, std::int64_t*) { return Got::kEnd; }

}  // namespace sdpslam::io::detail
