#include "sdpslam/daemon/paired_wheel_encoders.h"

namespace sdpslam::daemon {

int PairedWheelEncoders::update() {
  const int r = inner_.update();
  const hal::WheelEncoderSample s = inner_.latest();
  const bool left_new = s.left.has_sample && (!published_.left.has_sample || s.left.sequence != published_.left.sequence);
  const bool right_new =
      s.right.has_sample && (!published_.right.has_sample || s.right.sequence != published_.right.sequence);
  if (left_new && right_new) {
    published_ = s;
    ++pairs_;
  }
  bool left_stale = s.left.stale;
  bool right_stale = s.right.stale;
  if ((left_stale || right_stale) && bus_ != nullptr && bus_->wait_readable(0) > 0) {
    const std::int64_t newest = s.left.stamp_us > s.right.stamp_us ? s.left.stamp_us : s.right.stamp_us;
    auto stamp_fresh = [&](const hal::WheelTicks& w) {
      return w.has_sample && newest - w.stamp_us <= position_timeout_us_;
    };
    const bool l = left_stale && stamp_fresh(s.left);
    const bool rr = right_stale && stamp_fresh(s.right);
    if (l) left_stale = false;
    if (rr) right_stale = false;
    if (l || rr) ++overrides_;
  }
  published_.left.stale = left_stale;
  published_.right.stale = right_stale;
  return r;
}

}  // namespace sdpslam::daemon
