#pragma once
// Fixed-capacity object pools (after ETL's ipool/pool<T,N>, with o1heap's diagnostics).
//
//  - IPool: the size-erased base. Slot bookkeeping, free list, counters, self-check.
//    Callers that only need diagnostics take `const IPool&`.
//  - PoolOf<T>: typed API (create/destroy, handles) over storage provided by a subclass.
//  - Pool<T, N>: capacity in the type, storage inside the object (no heap ever).
//  - ArenaPool<T>: capacity chosen at init, storage carved once from an Arena.
//
// Cost: every operation is O(1) except invariants_hold(), which is O(capacity).
// Running out is an expected outcome: allocate()/create() return nullptr and bump
// oom_count(); nothing is thrown and nothing crashes. Releasing a pointer the pool does
// not own, or a slot that is already free, is refused (returns false) and counted in
// misuse_count().
#include <cstddef>
#include <cstdint>
#include <new>
#include <type_traits>
#include <utility>

#include "sdpslam/core/arena.h"
#include "sdpslam/core/handle.h"
#include "sdpslam/core/state_io.h"

namespace sdpslam {

class IPool {
 public:
  static constexpr std::uint32_t kNoSlot = 0xFFFFFFFFU;

  IPool(const IPool&) = delete;
  IPool& operator=(const IPool&) = delete;

  // Raw slot of slot_size() bytes, suitably aligned, not constructed; nullptr iff full.
  void* allocate() {
    if (free_head_ == kNoSlot) {
      ++oom_count_;
      return nullptr;
    }
    const std::uint32_t slot = free_head_;
    free_head_ = next_free_[slot];
    next_free_[slot] = kInUse;
    ++size_;
    if (size_ > peak_used_) peak_used_ = size_;
    return slot_address(slot);
  }

  // Returns true iff `p` is the start of a slot of this pool that is in use; the slot
  // becomes free (its generation advances, so handles to it go stale). Does not run a
  // destructor.
  bool release(const void* p) {
    const std::uint32_t slot = slot_of(p);
    if (slot == kNoSlot || next_free_[slot] != kInUse) {
      ++misuse_count_;
      return false;
    }
    next_free_[slot] = free_head_;
    free_head_ = slot;
    ++generation_[slot];
    --size_;
    return true;
  }

  std::uint32_t capacity() const { return capacity_; }
  std::uint32_t size() const { return size_; }
  std::uint32_t available() const { return capacity_ - size_; }
  bool full() const { return size_ == capacity_; }
  bool empty() const { return size_ == 0U; }
  std::size_t slot_size() const { return slot_size_; }
  // Bytes of state this pool holds: slots plus bookkeeping.
  std::size_t footprint_bytes() const {
    return static_cast<std::size_t>(capacity_) * (slot_size_ + 2U * sizeof(std::uint32_t));
  }

  // True iff `p` points at the start of one of this pool's slots that is in use.
  bool owns(const void* p) const {
    const std::uint32_t slot = slot_of(p);
    return slot != kNoSlot && next_free_[slot] == kInUse;
  }

  // Diagnostics that never decrease (o1heap style).
  std::uint32_t peak_used() const { return peak_used_; }
  std::uint32_t oom_count() const { return oom_count_; }
  std::uint32_t misuse_count() const { return misuse_count_; }

  // Slot index of an owned pointer, kNoSlot otherwise.
  std::uint32_t index_of(const void* p) const {
    const std::uint32_t slot = slot_of(p);
    return (slot != kNoSlot && next_free_[slot] == kInUse) ? slot : kNoSlot;
  }
  bool slot_in_use(std::uint32_t slot) const { return slot < capacity_ && next_free_[slot] == kInUse; }
  std::uint32_t slot_generation(std::uint32_t slot) const { return slot < capacity_ ? generation_[slot] : 0U; }

  // Full self-check: the free list is acyclic, stays in range, and together with the
  // in-use slots accounts for every slot exactly once; size and peak are consistent.
  bool invariants_hold() const {
    if (capacity_ > 0U && (storage_ == nullptr || next_free_ == nullptr || generation_ == nullptr)) return false;
    if (size_ > capacity_ || peak_used_ < size_ || peak_used_ > capacity_) return false;
    std::uint32_t in_use = 0U;
    for (std::uint32_t i = 0; i < capacity_; ++i) {
      if (next_free_[i] == kInUse) ++in_use;
    }
    if (in_use != size_) return false;
    std::uint32_t free_count = 0U;
    for (std::uint32_t s = free_head_; s != kNoSlot; s = next_free_[s]) {
      if (s >= capacity_ || ++free_count > capacity_ - in_use) return false;
    }
    return free_count + in_use == capacity_;
  }

  // Snapshot of the bookkeeping (state_io.h). The slots, free links and generations are
  // the storage's: an ArenaPool's travel with the arena.
  void transfer_state(StateIo& io) {
    io.fixed(capacity_, "pool capacity");
    io.value(size_);
    io.value(free_head_);
    io.value(peak_used_);
    io.value(oom_count_);
    io.value(misuse_count_);
  }

 protected:
  IPool() = default;
  ~IPool() = default;

  // Binds bookkeeping to storage; every slot starts free, counters start at zero.
  void bind(unsigned char* storage, std::size_t slot_size, std::uint32_t* next_free,
            std::uint32_t* generation, std::uint32_t capacity) {
    storage_ = storage;
    slot_size_ = slot_size;
    next_free_ = next_free;
    generation_ = generation;
    capacity_ = capacity;
    size_ = 0U;
    peak_used_ = 0U;
    oom_count_ = 0U;
    misuse_count_ = 0U;
    free_head_ = capacity > 0U ? 0U : kNoSlot;
    for (std::uint32_t i = 0; i < capacity; ++i) {
      next_free_[i] = (i + 1U < capacity) ? i + 1U : kNoSlot;
      generation_[i] = 0U;
    }
  }

  void* slot_address(std::uint32_t slot) const { return storage_ + static_cast<std::size_t>(slot) * slot_size_; }

 private:
  static constexpr std::uint32_t kInUse = 0xFFFFFFFEU;

  std::uint32_t slot_of(const void* p) const {
    if (p == nullptr || storage_ == nullptr) return kNoSlot;
    const auto addr = reinterpret_cast<std::uintptr_t>(p);
    const auto base = reinterpret_cast<std::uintptr_t>(storage_);
    if (addr < base) return kNoSlot;
    const std::uintptr_t offset = addr - base;
    if (offset % slot_size_ != 0U) return kNoSlot;
    const std::uintptr_t slot = offset / slot_size_;
    return slot < capacity_ ? static_cast<std::uint32_t>(slot) : kNoSlot;
  }

  unsigned char* storage_ = nullptr;
  std::size_t slot_size_ = 1U;
  std::uint32_t* next_free_ = nullptr;  // kInUse for a slot in use
  std::uint32_t* generation_ = nullptr;
  std::uint32_t capacity_ = 0U;
  std::uint32_t size_ = 0U;
  std::uint32_t free_head_ = kNoSlot;
  std::uint32_t peak_used_ = 0U;
  std::uint32_t oom_count_ = 0U;
  std::uint32_t misuse_count_ = 0U;
};

// Typed operations shared by Pool<T,N> and ArenaPool<T>.
template <typename T>
class PoolOf : public IPool {
 public:
  using value_type = T;
  static constexpr std::size_t kSlotSize = (sizeof(T) + alignof(T) - 1U) / alignof(T) * alignof(T);

  // Constructs a T in a free slot; nullptr iff the pool is full (oom_count() bumps).
  template <typename... Args>
  T* create(Args&&... args) {
    void* p = allocate();
    return p != nullptr ? new (p) T(std::forward<Args>(args)...) : nullptr;
  }

  // Destroys and releases; false (and misuse_count() bumps) iff `p` is not in use here.
  bool destroy(T* p) {
    if (!owns(p)) return release(p);  // refused and counted
    p->~T();
    return release(p);
  }

  Handle<T> handle_of(const T* p) const {
    const std::uint32_t slot = index_of(p);
    if (slot == kNoSlot) return Handle<T>::invalid();
    return Handle<T>{slot, slot_generation(slot)};
  }

  // The object behind `h`, or nullptr iff the handle is invalid, out of range, or stale
  // (its slot was released since the handle was taken).
  T* get(Handle<T> h) {
    if (!slot_in_use(h.index) || slot_generation(h.index) != h.generation) return nullptr;
    return static_cast<T*>(slot_address(h.index));
  }
  const T* get(Handle<T> h) const { return const_cast<PoolOf*>(this)->get(h); }

  // Object in slot `index` if that slot is in use, else nullptr (for iteration).
  T* at_index(std::uint32_t index) { return slot_in_use(index) ? static_cast<T*>(slot_address(index)) : nullptr; }
  const T* at_index(std::uint32_t index) const { return const_cast<PoolOf*>(this)->at_index(index); }

  // Destroys every live object; counters other than size are kept.
  void clear() {
    for (std::uint32_t i = 0; i < capacity(); ++i) {
      if (T* p = at_index(i)) destroy(p);
    }
  }

 protected:
  PoolOf() = default;
  ~PoolOf() = default;
};

// Capacity N in the type, storage inside the object: put it in static storage or inside
// another fixed-size object, never on a small stack.
template <typename T, std::uint32_t N>
class Pool final : public PoolOf<T> {
  static_assert(N >= 1U && N < 0xFFFFFFF0U, "Pool capacity out of range");

 public:
  Pool() { this->bind(reinterpret_cast<unsigned char*>(storage_), PoolOf<T>::kSlotSize, next_free_, generation_, N); }
  ~Pool() { this->clear(); }

 private:
  alignas(T) unsigned char storage_[PoolOf<T>::kSlotSize * N];
  std::uint32_t next_free_[N];
  std::uint32_t generation_[N];
};

// Capacity chosen at init; storage carved once from an Arena.
template <typename T>
class ArenaPool final : public PoolOf<T> {
 public:
  ArenaPool() = default;
  ~ArenaPool() { this->clear(); }

  // Returns false iff the arena cannot hold `capacity` slots (nothing is then bound and
  // the pool has capacity 0). Call once, at init.
  bool init(Arena& arena, std::uint32_t capacity) {
    if (capacity >= 0xFFFFFFF0U) return false;
    auto* storage = static_cast<unsigned char*>(arena.allocate(PoolOf<T>::kSlotSize * capacity, alignof(T)));
    auto* next_free = static_cast<std::uint32_t*>(arena.allocate(sizeof(std::uint32_t) * capacity, alignof(std::uint32_t)));
    auto* generation = static_cast<std::uint32_t*>(arena.allocate(sizeof(std::uint32_t) * capacity, alignof(std::uint32_t)));
    if (storage == nullptr || next_free == nullptr || generation == nullptr) {
      this->bind(nullptr, PoolOf<T>::kSlotSize, nullptr, nullptr, 0U);
      return false;
    }
    this->bind(storage, PoolOf<T>::kSlotSize, next_free, generation, capacity);
    return true;
  }
};

}  // namespace sdpslam
