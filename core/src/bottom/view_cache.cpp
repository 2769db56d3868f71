#include "sdpslam/core/bottom/view_cache.h"

namespace sdpslam {

std::size_t ViewCache::required_arena_bytes(std::uint32_t slots) { return Arena::bytes_for<Slot>(slots); }

bool ViewCache::init(Arena& arena, std::uint32_t slots) {
  slots_ = nullptr;
  if (slots < 16U || (slots & (slots - 1U)) != 0U) return false;
  Slot* s = arena.allocate_array<Slot>(slots);
  if (s == nullptr) return false;
  for (std::uint32_t i = 0; i < slots; ++i) s[i] = Slot{0U, 0U, CellObservation{}};
  std::uint32_t bits = 0U;
  while ((1U << bits) < slots) ++bits;
  slots_ = s;
  mask_ = slots - 1U;
  shift_ = 64U - bits;
  limit_ = slots / 4U * 3U;
  used_ = 0U;
  generation_ = 0U;
  map_ = nullptr;
  particle_ = kNoNode;
  hits_ = misses_ = 0U;
  return true;
}

void ViewCache::begin(const DpMap& map, NodeId particle) {
  map_ = &map;
  particle_ = particle;
  used_ = 0U;
  // Generation 0 marks never-used slots; after 2^31 - 1 bursts every slot is cleared once.
  if (++generation_ == kSeen) {
    for (std::uint32_t i = 0; i <= mask_; ++i) slots_[i].generation = 0U;
    generation_ = 1U;
  }
}

bool ViewCache::lookup(std::int32_t ix, std::int32_t iy, CellObservation* out) {
  const std::uint64_t key =
      (static_cast<std::uint64_t>(static_cast<std::uint32_t>(ix)) << 32U) | static_cast<std::uint32_t>(iy);
  std::uint32_t i = static_cast<std::uint32_t>((key * 0x9E3779B97F4A7C15ULL) >> shift_);
  for (;;) {
    Slot& s = slots_[i];
    if ((s.generation & ~kSeen) != generation_) break;  // free in this burst: not cached
    if (s.key == key) {
      ++hits_;
      if ((s.generation & kSeen) == 0U) return false;
      *out = s.value;
      return true;
    }
    i = (i + 1U) & mask_;
  }
  ++misses_;
  CellObservation v;
  const bool seen = map_->lookup(particle_, ix, iy, &v);
  if (used_ < limit_) {
    slots_[i] = Slot{key, generation_ | (seen ? kSeen : 0U), v};
    ++used_;
  }
  if (seen) *out = v;
  return seen;
}


void ViewCache::transfer_state(StateIo& io) {
  io.section("view_cache");
  io.value(used_);
  io.value(generation_);
  io.arena_pointer(map_, "view cache map");
  io.value(particle_);
  io.value(hits_);
  io.value(misses_);
}

}  // namespace sdpslam
