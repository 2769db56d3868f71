#include "sdpslam/drivers/can_wheel_encoders.h"

namespace sdpslam::drivers {
namespace {
// Exact standard data frame: id bits, IDE and RTR must all match.
constexpr std::uint32_t kExactStandardMask =
    hal::CanFrame::kStandardMask | hal::CanFrame::kExtendedFlag | hal::CanFrame::kRtrFlag;
constexpr std::uint32_t kODriveNodeMask = 0x7E0u | hal::CanFrame::kExtendedFlag | hal::CanFrame::kRtrFlag;
}  // namespace

bool parse_encoder_protocol(std::string_view name, EncoderProtocol& out) {
  if (name == "canopen" || name == "cia406") {
    out = EncoderProtocol::kCanOpen;
    return true;
  }
  if (name == "odrive") {
    out = EncoderProtocol::kODrive;
    return true;
  }
  return false;
}

const char* to_string(EncoderProtocol p) {
  return p == EncoderProtocol::kCanOpen ? "canopen" : "odrive";
}

bool add_receive_filters(const CanWheelEncoderConfig& config, SocketCanOptions& bus) {
  CanIdFilter add[6];
  int n = 0;
  if (config.protocol == EncoderProtocol::kCanOpen) {
    for (std::uint8_t node : {config.canopen.left_node, config.canopen.right_node}) {
      add[n++] = {canopen::kTpdo1Base + node, kExactStandardMask};
      add[n++] = {canopen::kHeartbeatBase + node, kExactStandardMask};
      add[n++] = {canopen::kEmcyBase + node, kExactStandardMask};
    }
  } else {
    for (std::uint8_t node : {config.odrive.left_node, config.odrive.right_node}) {
      add[n++] = {odrive::make_id(node, 0), kODriveNodeMask};
    }
  }
  if (bus.filter_count < 0 || bus.filter_count + n > SocketCanOptions::kMaxFilters) return false;
  for (int i = 0; i < n; ++i) bus.filters[bus.filter_count++] = add[i];
  return true;
}

CanWheelEncoders::CanWheelEncoders(hal::CanBus& bus, const hal::MonotonicClock& clock,
                                   const CanWheelEncoderConfig& config)
    : protocol_(config.protocol) {
  if (protocol_ == EncoderProtocol::kCanOpen) {
    canopen_.emplace(bus, clock, config.canopen);
  } else {
    odrive_.emplace(bus, clock, config.odrive);
  }
}

int CanWheelEncoders::start() { return canopen_ ? canopen_->start() : (odrive_->options_ok() ? 1 : -1); }

int CanWheelEncoders::update() { return canopen_ ? canopen_->update() : odrive_->update(); }

hal::WheelEncoderSample CanWheelEncoders::latest() const {
  return canopen_ ? canopen_->latest() : odrive_->latest();
}

}  // namespace sdpslam::drivers
