#pragma once
// Index-based handle for objects that live in a pool.
//
// Pooled objects refer to each other by Handle rather than by pointer: a handle is
// 8 bytes, trivially copyable, survives relocation of the pool's storage, and carries
// the slot's generation so that a handle to a released (and possibly reused) slot is
// detected as stale by Pool::get() instead of silently aliasing the new occupant.
#include <cstdint>

namespace sdpslam {

template <typename T>
struct Handle {
  static constexpr std::uint32_t kInvalidIndex = 0xFFFFFFFFU;

  std::uint32_t index = kInvalidIndex;
  std::uint32_t generation = 0U;

  constexpr bool valid() const { return index != kInvalidIndex; }
  static constexpr Handle invalid() { return Handle{}; }

  friend constexpr bool operator==(const Handle& a, const Handle& b) {
    return a.index == b.index && a.generation == b.generation;
  }
  friend constexpr bool operator!=(const Handle& a, const Handle& b) { return !(a == b); }
};

}  // namespace sdpslam
