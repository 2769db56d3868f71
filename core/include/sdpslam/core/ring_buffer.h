#pragma once
// Fixed-capacity FIFO ring with storage inside the object.
//
// Two ways to meet a full ring, chosen per call: push() refuses the newest element
// (returns false, bumps refused_count()); push_overwrite() drops the oldest (bumps
// overwritten_count()) — the right choice for sensor queues where fresh data wins.
// T must be default-constructible and copy-assignable; slots are kept constructed.
#include <cstddef>
#include <cstdint>

namespace sdpslam {

template <typename T, std::size_t N>
class RingBuffer {
  static_assert(N >= 1U, "RingBuffer capacity must be at least 1");

 public:
  bool push(const T& v) {
    if (size_ == N) {
      ++refused_count_;
      return false;
    }
    slots_[(head_ + size_) % N] = v;
    ++size_;
    return true;
  }
  void push_overwrite(const T& v) {
    if (size_ == N) {
      head_ = (head_ + 1U) % N;
      --size_;
      ++overwritten_count_;
    }
    push(v);
  }
  // Copies the oldest element into `out` and removes it; false iff empty.
  bool pop(T& out) {
    if (size_ == 0U) return false;
    out = slots_[head_];
    head_ = (head_ + 1U) % N;
    --size_;
    return true;
  }
  // i = 0 is the oldest element. Precondition: i < size().
  T& operator[](std::size_t i) { return slots_[(head_ + i) % N]; }
  const T& operator[](std::size_t i) const { return slots_[(head_ + i) % N]; }
  const T& front() const { return slots_[head_]; }
  const T& back() const { return slots_[(head_ + size_ - 1U) % N]; }
  void clear() {
    head_ = 0U;
    size_ = 0U;
  }

  std::size_t size() const { return size_; }
  static constexpr std::size_t capacity() { return N; }
  bool empty() const { return size_ == 0U; }
  bool full() const { return size_ == N; }
  std::uint32_t refused_count() const { return refused_count_; }
  std::uint32_t overwritten_count() const { return overwritten_count_; }

 private:
  T slots_[N]{};
  std::size_t head_ = 0U;
  std::size_t size_ = 0U;
  std::uint32_t refused_count_ = 0U;
  std::uint32_t overwritten_count_ = 0U;
};

}  // namespace sdpslam
