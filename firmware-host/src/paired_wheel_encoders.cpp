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
  published_.left.stale = s.left.stale;
  published_.right.stale = s.right.stale;
  return r;
}

}  // namespace sdpslam::daemon
