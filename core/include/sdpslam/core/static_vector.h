#pragma once
// Fixed-capacity vector with storage inside the object (after etl::vector<T, N>).
//
// push_back()/emplace_back() return false (and bump overflow_count()) when full instead
// of growing; nothing here ever touches the heap. Elements are constructed in place and
// destroyed on pop/clear/destruction.
#include <cstddef>
#include <cstdint>
#include <new>
#include <type_traits>
#include <utility>

namespace sdpslam {

template <typename T, std::size_t N>
class StaticVector {
  static_assert(N >= 1U, "StaticVector capacity must be at least 1");

 public:
  using value_type = T;
  using iterator = T*;
  using const_iterator = const T*;

  StaticVector() = default;
  StaticVector(const StaticVector& other) { copy_from(other); }
  StaticVector& operator=(const StaticVector& other) {
    if (this != &other) {
      clear();
      copy_from(other);
    }
    return *this;
  }
  ~StaticVector() { clear(); }

  // False iff full (overflow_count() bumps).
  bool push_back(const T& v) { return emplace_back(v); }
  template <typename... Args>
  bool emplace_back(Args&&... args) {
    if (size_ == N) {
      ++overflow_count_;
      return false;
    }
    new (&data()[size_]) T(std::forward<Args>(args)...);
    ++size_;
    return true;
  }
  // Removes the last element; false iff empty.
  bool pop_back() {
    if (size_ == 0U) return false;
    --size_;
    data()[size_].~T();
    return true;
  }
  // Removes element i by moving the last one into its place (O(1), order not kept).
  bool swap_remove(std::size_t i) {
    if (i >= size_) return false;
    if (i + 1U != size_) data()[i] = std::move(data()[size_ - 1U]);
    return pop_back();
  }
  // Shrinks to `n` elements, or grows with value-initialised elements; false iff n > N.
  bool resize(std::size_t n) {
    if (n > N) {
      ++overflow_count_;
      return false;
    }
    while (size_ > n) pop_back();
    while (size_ < n) emplace_back();
    return true;
  }
  void clear() {
    while (size_ > 0U) pop_back();
  }

  T& operator[](std::size_t i) { return data()[i]; }
  const T& operator[](std::size_t i) const { return data()[i]; }
  T& back() { return data()[size_ - 1U]; }
  const T& back() const { return data()[size_ - 1U]; }
  T& front() { return data()[0]; }
  const T& front() const { return data()[0]; }

  T* data() { return reinterpret_cast<T*>(storage_); }
  const T* data() const { return reinterpret_cast<const T*>(storage_); }
  iterator begin() { return data(); }
  iterator end() { return data() + size_; }
  const_iterator begin() const { return data(); }
  const_iterator end() const { return data() + size_; }

  std::size_t size() const { return size_; }
  static constexpr std::size_t capacity() { return N; }
  std::size_t available() const { return N - size_; }
  bool empty() const { return size_ == 0U; }
  bool full() const { return size_ == N; }
  // Refused insertions since construction; never decreases.
  std::uint32_t overflow_count() const { return overflow_count_; }

 private:
  void copy_from(const StaticVector& other) {
    for (const T& v : other) emplace_back(v);
    overflow_count_ = other.overflow_count_;
  }

  alignas(T) unsigned char storage_[sizeof(T) * N];
  std::size_t size_ = 0U;
  std::uint32_t overflow_count_ = 0U;
};

}  // namespace sdpslam
