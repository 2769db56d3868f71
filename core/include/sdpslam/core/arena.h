#pragma once
// Init-time bump allocator over one caller-provided buffer.
//
// Contract: the core takes all of its run-time-sized storage (pools whose capacity is
// chosen at init, grids, tables) from an Arena while it is being initialised, and never
// afterwards. An Arena never frees individual blocks; reset() forgets everything.
// Ownership: the buffer belongs to the caller and must outlive every block carved from it.
#include <cstddef>
#include <cstdint>
#include <new>  // placement new only; never allocates

namespace sdpslam {

class Arena {
 public:
  Arena() = default;
  Arena(void* buffer, std::size_t size_bytes) { reset(buffer, size_bytes); }

  void reset(void* buffer, std::size_t size_bytes) {
    base_ = static_cast<unsigned char*>(buffer);
    capacity_bytes_ = buffer != nullptr ? size_bytes : 0U;
    used_bytes_ = 0U;
  }

  // Returns a block of `size_bytes` aligned to `align` (a power of two), or nullptr iff
  // the arena has too little room left (oom_count() is then incremented) or `align` is
  // not a power of two. A zero-size request returns a valid, unique-enough pointer.
  void* allocate(std::size_t size_bytes, std::size_t align) {
    if (align == 0U || (align & (align - 1U)) != 0U || base_ == nullptr) {
      ++oom_count_;
      return nullptr;
    }
    const std::uintptr_t start = reinterpret_cast<std::uintptr_t>(base_) + used_bytes_;
    const std::uintptr_t aligned = (start + (align - 1U)) & ~static_cast<std::uintptr_t>(align - 1U);
    const std::size_t padding = static_cast<std::size_t>(aligned - start);
    if (padding > capacity_bytes_ - used_bytes_ || size_bytes > capacity_bytes_ - used_bytes_ - padding) {
      ++oom_count_;
      return nullptr;
    }
    used_bytes_ += padding + size_bytes;
    return reinterpret_cast<void*>(aligned);
  }

  // Bytes to budget for allocate_array<T>(count): the array, its worst alignment padding
  // and a margin (for required_arena_bytes() functions summing many arrays).
  template <typename T>
  static constexpr std::size_t bytes_for(std::size_t count) {
    return sizeof(T) * count + alignof(T) + 64U;
  }

  // Typed array of `count` default-initialised Ts; nullptr iff out of room.
  template <typename T>
  T* allocate_array(std::size_t count) {
    constexpr std::size_t kElem = sizeof(T) > 0U ? sizeof(T) : 1U;
    if (count > available_bytes() / kElem) {  // also rules out overflow of count * kElem
      ++oom_count_;
      return nullptr;
    }
    const std::size_t bytes = count * kElem;
    void* p = allocate(bytes, alignof(T));
    if (p == nullptr) return nullptr;
    T* typed = static_cast<T*>(p);
    for (std::size_t done = 0; done < bytes; done += kElem) new (&typed[done / kElem]) T();
    return typed;
  }

  // Where the next block would start (before alignment): blocks carved between two
  // readings of it lie between them.
  unsigned char* cursor() const { return base_ != nullptr ? base_ + used_bytes_ : nullptr; }
  std::size_t capacity_bytes() const { return capacity_bytes_; }
  std::size_t used_bytes() const { return used_bytes_; }
  std::size_t available_bytes() const { return capacity_bytes_ - used_bytes_; }
  std::uint32_t oom_count() const { return oom_count_; }

 private:
  unsigned char* base_ = nullptr;
  std::size_t capacity_bytes_ = 0U;
  std::size_t used_bytes_ = 0U;
  std::uint32_t oom_count_ = 0U;
};

}  // namespace sdpslam
