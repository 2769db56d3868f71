// enable_bag_formats() (io/bags.h): LogReader's bag sources, as this build has them.
#include "bag_common.h"
#include "ros2_bag_source.h"
#include "rosbag_source.h"
#include "sdpslam/io/bags.h"

namespace sdpslam::io {

void enable_bag_formats() {
  detail::g_make_ros1_source = []() -> std::unique_ptr<detail::BagSource> {
    return std::make_unique<detail::RosBagSource>();
  };
  detail::g_make_ros2_source = []() -> std::unique_ptr<detail::BagSource> {
    return std::make_unique<detail::Ros2BagSource>();
  };
}

}  // namespace sdpslam::io
