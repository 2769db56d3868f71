// The bag plugin's one exported function (bag_common.h: BagPlugin): the ROS 1 and ROS 2
// bag readers and the ROS 2 writer of this build, for the program that loads it
// (bags_enable.cpp). Everything else in the plugin is hidden (CMake: visibility hidden).
#include "bag_common.h"
#include "ros2_bag_source.h"
#include "rosbag_source.h"

#ifndef SDPSLAM_BAG_PLUGIN_BUILD
#error "SDPSLAM_BAG_PLUGIN_BUILD names the build (tools/bags/CMakeLists.txt)"
#endif

namespace {

using sdpslam::io::detail::BagPlugin;
using sdpslam::io::detail::BagSource;

std::unique_ptr<BagSource> make_ros1() { return std::make_unique<sdpslam::io::detail::RosBagSource>(); }
std::unique_ptr<BagSource> make_ros2() { return std::make_unique<sdpslam::io::detail::Ros2BagSource>(); }

}  // namespace

extern "C" __attribute__((visibility("default"))) const BagPlugin* sdpslam_bag_plugin_v1() {
  static const BagPlugin plugin{SDPSLAM_BAG_PLUGIN_BUILD, &make_ros1, &make_ros2,
                                &sdpslam::io::detail::make_ros2_writer, sdpslam::io::detail::ros2_bags_built()};
  return &plugin;
}
