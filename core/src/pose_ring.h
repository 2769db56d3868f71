#pragma once
// Stamped poses in time order, in a ring of fixed capacity carved from an Arena.
//
// SDP-SLAM keeps here the poses the bottom filter commits (PoseSink), in their segment's
// frame, until their level becomes permanent: a level's poses are those stamped within
// its (start, end], and they leave from the oldest end (drop_through()). A full ring
// refuses the newest pose (push() is false; the caller counts the gap): the oldest are
// still needed by the levels that hold them.
#include <cstddef>
#include <cstdint>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/pose2.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

class PoseRing {
 public:
  PoseRing() = default;
  PoseRing(const PoseRing&) = delete;
  PoseRing& operator=(const PoseRing&) = delete;

  static std::size_t required_bytes(std::uint32_t capacity) { return Arena::bytes_for<StampedPose>(capacity); }
  // False iff capacity is 0 or the arena is too small.
  bool init(Arena& arena, std::uint32_t capacity) {
    slots_ = nullptr;
    head_ = 0U;
    count_ = 0U;
    if (capacity == 0U) return false;
    slots_ = arena.allocate_array<StampedPose>(capacity);
    capacity_ = slots_ != nullptr ? capacity : 0U;
    return slots_ != nullptr;
  }

  // Appends a pose (stamps in time order); false, changing nothing, when full.
  bool push(std::int64_t stamp_us, const Pose2& pose) {
    if (count_ == capacity_) return false;
    slots_[(head_ + count_) % capacity_] = StampedPose{stamp_us, pose};
    ++count_;
    return true;
  }
  // Drops the oldest poses stamped at or before stamp_us.
  void drop_through(std::int64_t stamp_us) {
    while (count_ > 0U && slots_[head_].stamp_us <= stamp_us) {
      head_ = (head_ + 1U) % capacity_;
      --count_;
    }
  }
  // f(stamp_us, pose) for every pose stamped in (after_us, through_us], oldest first.
  template <class F>
  void for_each_between(std::int64_t after_us, std::int64_t through_us, F&& f) const {
    for (std::uint32_t k = 0; k < count_; ++k) {
      const StampedPose& e = slots_[(head_ + k) % capacity_];
      if (e.stamp_us > after_us && e.stamp_us <= through_us) f(e.stamp_us, e.pose);
    }
  }

  std::uint32_t size() const { return count_; }
  std::uint32_t capacity() const { return capacity_; }

  // The ring's head and count, for snapshots (state_io.h); the slots travel with the arena.
  void transfer_state(StateIo& io) {
    io.value(head_);
    io.value(count_);
  }

 private:
  StampedPose* slots_ = nullptr;
  std::uint32_t capacity_ = 0U;
  std::uint32_t head_ = 0U;
  std::uint32_t count_ = 0U;
};

}  // namespace sdpslam
