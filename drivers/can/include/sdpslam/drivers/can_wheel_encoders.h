#pragma once
// Wheel encoders on CAN selected by configuration: one object that is either a
// CanOpenEncoderPair or an ODriveEncoderPair (storage for both inside, no heap), plus the
// CAN_RAW receive filters the chosen protocol needs.
#include <cstdint>
#include <optional>
#include <string_view>

#include "sdpslam/drivers/canopen_encoder_pair.h"
#include "sdpslam/drivers/odrive_encoder_pair.h"
#include "sdpslam/drivers/socketcan_bus.h"

namespace sdpslam::drivers {

enum class EncoderProtocol : std::uint8_t { kCanOpen, kODrive };

// "canopen" / "cia406" -> kCanOpen, "odrive" -> kODrive. False (out untouched) otherwise.
bool parse_encoder_protocol(std::string_view name, EncoderProtocol& out);
const char* to_string(EncoderProtocol p);

struct CanWheelEncoderConfig {
  EncoderProtocol protocol = EncoderProtocol::kCanOpen;
  CanOpenEncoderOptions canopen;
  ODriveEncoderOptions odrive;
};

// Appends to `bus` the receive filters of the configured protocol: CANopen TPDO1,
// heartbeat and EMCY of both nodes (6 exact standard ids), ODrive every command of both
// axes (2 node masks). Extended and RTR frames are excluded by the masks. Returns false
// (and appends nothing) iff they do not fit in SocketCanOptions::kMaxFilters.
bool add_receive_filters(const CanWheelEncoderConfig& config, SocketCanOptions& bus);

class CanWheelEncoders final : public hal::WheelEncoderSource {
 public:
  CanWheelEncoders(hal::CanBus& bus, const hal::MonotonicClock& clock, const CanWheelEncoderConfig& config);
  // CANopen: sends NMT start (see CanOpenEncoderPair::start). ODrive: nothing to do, 1.
  int start();
  int update() override;
  hal::WheelEncoderSample latest() const override;
  EncoderProtocol protocol() const { return protocol_; }
  // The active handler (null for the other protocol), for its stats.
  const CanOpenEncoderPair* canopen() const { return canopen_ ? &*canopen_ : nullptr; }
  const ODriveEncoderPair* odrive() const { return odrive_ ? &*odrive_ : nullptr; }

 private:
  EncoderProtocol protocol_;
  std::optional<CanOpenEncoderPair> canopen_;
  std::optional<ODriveEncoderPair> odrive_;
};

}  // namespace sdpslam::drivers
