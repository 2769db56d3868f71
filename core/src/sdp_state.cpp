// SdpSlamImpl snapshots: the whole engine state as a stream (core/state_io.h).
//
// Layout of the stream:
//   header     tag, format, build fingerprint (the sizes of the engine's objects and the
//              byte order), the size of the arena region init() carved and where the
//              three engine objects sit in it;
//   region     the region's bytes, less the three objects' (they hold pointers and
//              vtable pointers, which stay as this process's init() set them);
//   members    SdpSlamImpl's, then each part's own (transfer_state), with a tag per part;
//   end tag.
// Reading compares the header with this engine before it writes anything, so that a
// stream of another build or other options changes nothing and says why.
#include <cstdio>

#include "sdp_slam_impl.h"

namespace sdpslam {
namespace {

constexpr std::uint32_t kStateFormat = 1U;

// What must be equal between the writer's build and the reader's.
struct Fingerprint {
  std::uint32_t byte_order = 0x01020304U;
  std::uint32_t pointer_bytes = static_cast<std::uint32_t>(sizeof(void*));
  std::uint64_t engine_bytes = sizeof(SdpSlamImpl);
  std::uint64_t filter_bytes = sizeof(DpSlamFilter);
  std::uint64_t icp_bytes = sizeof(Icp2d);
  std::uint64_t segmenter_bytes = sizeof(Segmenter);
  std::uint64_t max_beams = capacity::kMaxBeams;
};

bool operator==(const Fingerprint& a, const Fingerprint& b) {
  return a.byte_order == b.byte_order && a.pointer_bytes == b.pointer_bytes && a.engine_bytes == b.engine_bytes &&
         a.filter_bytes == b.filter_bytes && a.icp_bytes == b.icp_bytes && a.segmenter_bytes == b.segmenter_bytes &&
         a.max_beams == b.max_beams;
}

// A block of the region that is skipped (an engine object), by offset.
struct Hole {
  std::uint64_t offset;
  std::uint64_t bytes;
};

}  // namespace

std::uint64_t SdpSlamImpl::state_bytes() const {
  if (!initialised_) return 0U;
  struct Counter final : StateWriter {
    bool write(const void*, std::size_t) override { return true; }
  } counter;
  // save_state() is const in effect; transfer_state() shares code with loading.
  StateIo io(counter, state_begin_, static_cast<std::size_t>(state_end_ - state_begin_));
  const_cast<SdpSlamImpl*>(this)->transfer_state(io);
  return io.ok() ? io.byte_count() : 0U;
}

bool SdpSlamImpl::save_state(StateWriter& writer) {
  if (!initialised_) {
    std::snprintf(why_, sizeof why_, "snapshot: engine not initialised");
    return false;
  }
  StateIo io(writer, state_begin_, static_cast<std::size_t>(state_end_ - state_begin_));
  transfer_state(io);
  if (!io.ok()) {
    std::snprintf(why_, sizeof why_, "snapshot: %s", io.why());
    return false;
  }
  return true;
}

bool SdpSlamImpl::load_state(StateReader& reader) {
  if (!initialised_) {
    std::snprintf(why_, sizeof why_, "snapshot: engine not initialised");
    return false;
  }
  StateIo io(reader, state_begin_, static_cast<std::size_t>(state_end_ - state_begin_));
  transfer_state(io);
  if (!io.ok()) {
    std::snprintf(why_, sizeof why_, "snapshot refused: %s", io.why());
    // A refusal in the header changed nothing, but one further on left a mix of two
    // states: the engine is not trusted either way.
    initialised_ = false;
    return false;
  }
  return true;
}

void SdpSlamImpl::transfer_state(StateIo& io) {
  // ---- header
  io.section("sdpslam state");
  std::uint32_t format = kStateFormat;
  io.value(format);
  if (io.ok() && format != kStateFormat) io.fail("snapshot format differs", nullptr);
  Fingerprint mine;
  Fingerprint theirs = mine;
  io.value(theirs);
  if (io.ok() && !(theirs == mine)) io.fail("written by another build (object sizes or byte order differ)", nullptr);
  const auto region = static_cast<std::uint64_t>(state_end_ - state_begin_);
  const auto offset = [this](const void* p) {
    return static_cast<std::uint64_t>(static_cast<const unsigned char*>(p) - state_begin_);
  };
  // The engine objects in address order (init() carves them in this order, first).
  const Hole holes[3] = {{offset(filter_), sizeof(DpSlamFilter)},
                         {offset(icp_), sizeof(Icp2d)},
                         {offset(segmenter_), sizeof(Segmenter)}};
  std::uint64_t layout[7] = {region, holes[0].offset, holes[0].bytes, holes[1].offset,
                             holes[1].bytes, holes[2].offset, holes[2].bytes};
  std::uint64_t their_layout[7];
  for (std::size_t i = 0; i < 7U; ++i) their_layout[i] = layout[i];
  io.value(their_layout);
  for (std::size_t i = 0; i < 7U && io.ok(); ++i) {
    if (their_layout[i] != layout[i]) io.fail("arena layout differs (other options)", nullptr);
  }
  if (!io.ok()) return;

  // ---- region
  io.section("arena");
  std::uint64_t at = 0U;
  for (const Hole& h : holes) {
    if (h.offset < at || h.offset + h.bytes > region) {
      io.fail("engine objects outside the arena region", nullptr);
      return;
    }
    io.bytes(state_begin_ + at, static_cast<std::size_t>(h.offset - at));
    // The object's bytes travel as its members below; the stream keeps the place so
    // that the region's offsets read straight: zeros are written, and read into scratch.
    unsigned char hole[256] = {};
    for (std::uint64_t n = h.bytes; n > 0U && io.ok();) {
      const std::size_t k = n < sizeof hole ? static_cast<std::size_t>(n) : sizeof hole;
      io.bytes(hole, k);
      n -= k;
    }
    at = h.offset + h.bytes;
  }
  io.bytes(state_begin_ + at, static_cast<std::size_t>(region - at));

  // ---- members
  io.section("engine");
  filter_->transfer_state(io);
  icp_->transfer_state(io);
  segmenter_->transfer_state(io);
  graph_.transfer_state(io);
  skeletons_.transfer_state(io);
  rng_.transfer_state(io);
  io.value(stats_);
  store_.transfer_state(io);
  ring_.transfer_state(io);
  loop_closure_.transfer_state(io);
  io.value(release_count_);
  io.value(releases_deferred_);
  transfer_.transfer_state(io);
  io.value(copy_count_);
  permanent_map_.transfer_state(io);
  io.section("segment");
  io.value(started_);
  io.value(segment_start_pose_);
  io.value(window_radius_m_);
  io.value(segment_start_stamp_us_);
  io.value(segment_scans_);
  io.value(scan_requests_);
  io.value(previous_scan_requests_);
  io.value(later_scan_requests_);
  io.value(previous_later_scan_requests_);
  io.value(observations_released_);
  io.value(segment_observations_released_);
  io.value(segment_observations_used_);
  io.value(segment_observations_refused_);
  io.value(last_processed_stamp_us_);
  io.value(seg_box_);
  io.section("round");
  io.value(round_active_);
  io.value(deferred_in_a_row_);
  io.value(eval_cursor_);
  io.value(rounds_in_segment_);
  io.value(round_sum_);
  io.value(round_sq_);
  io.value(round_samples_);
  io.value(best_top_);
  io.value(current_frame_);
  io.section("end");
}

}  // namespace sdpslam
