#pragma once
// Result of the pure CAN codecs (canopen_codec.h, odrive_codec.h): a decoder takes a
// frame and returns kOk with the value written, or the reason the frame is not the one
// asked for (the output is then untouched).
#include <cstdint>

namespace sdpslam::drivers {

enum class CanDecodeError : std::uint8_t {
  kOk,
  kWrongId,      // identifier is not the expected object for this node/command
  kExtendedId,   // a 29-bit frame where an 11-bit one was expected
  kRtr,          // a remote request carries no data
  kErrorFrame,   // an error frame is not a protocol message
  kWrongLength,  // DLC not what the object defines
  kBadValue,     // payload outside the object's value set (e.g. unknown NMT state, NaN)
  kBadNode,      // node id outside the protocol's range
};

const char* to_string(CanDecodeError e);

}  // namespace sdpslam::drivers
