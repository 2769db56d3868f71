#pragma once
// Source of wheel encoder counts for a differential-drive base (left and right wheel).
// Implementations: CANopen CiA 406 encoders, ODrive axes (drivers/can), fakes in tests.
#include <cstdint>

namespace sdpslam::hal {

enum class WheelSide : std::uint8_t { kLeft = 0, kRight = 1 };

// Latest reading of one wheel's counter.
struct WheelTicks {
  // Raw counter as the encoder reports it, modulo 2^counter_bits. Consumers take
  // differences modulo 2^counter_bits as signed values (protocols.md §3), never
  // absolute values.
  std::uint32_t raw_count = 0;
  std::uint8_t counter_bits = 32;  // 16 or 32
  // Monotonic-clock time the sample was received (or produced by the encoder).
  std::int64_t stamp_us = 0;
  // Increments with every new sample; lets a consumer see whether it already used it.
  std::uint32_t sequence = 0;
  bool has_sample = false;  // false until the first sample arrives
  // True when the wheel's data stopped arriving (no position within the source's
  // timeout, lost heartbeat, node not operational). A stale wheel must not be used.
  bool stale = true;

  bool fresh() const { return has_sample && !stale; }
};

struct WheelEncoderSample {
  WheelTicks left;
  WheelTicks right;
  bool both_fresh() const { return left.fresh() && right.fresh(); }
};

class WheelEncoderSource {
 public:
  virtual ~WheelEncoderSource() = default;
  // Does the source's pending non-blocking work (drain received frames, send periodic
  // requests, re-evaluate freshness against the clock). Returns the number of new wheel
  // samples (>= 0), or < 0 when the transport failed.
  virtual int update() = 0;
  // The latest reading of both wheels, freshness evaluated at the last update().
  virtual WheelEncoderSample latest() const = 0;
};

}  // namespace sdpslam::hal
