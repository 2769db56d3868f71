#pragma once
// The engine's complete state as a byte stream, for snapshots that let a mapping run
// continue after a restart (SdpSlam::save_state / load_state).
//
// Design: a snapshot is only ever read back into an engine initialised with the same
// options, so the arena has the same layout (every block at the same offset) and every
// pointer init() set is already right. The stream therefore carries
//  - the arena's used bytes verbatim, less the blocks that hold engine objects (those
//    contain pointers and, for polymorphic members, vtable pointers of the process that
//    wrote them);
//  - each object's mutable members, listed by the object itself (transfer_state()),
//    through one function for both directions so that writing and reading cannot
//    disagree on the order;
//  - pointers that change after init (a pair of buffers swapped each step, a search's
//    source) as offsets from the arena's base;
//  - tags between the parts, so that a stream from another build is refused at the first
//    part that differs, naming it, instead of being read into the wrong members.
// Integrity (checksums) and versioning of the file are the caller's: the core writes to
// and reads from a StateWriter / StateReader and never touches storage itself.
//
// Not for exchange between builds: values are written in the machine's byte order and
// structures in its layout; the header SdpSlam writes (build fingerprint, arena size)
// makes another build's stream fail cleanly. No heap, no OS call.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <type_traits>

namespace sdpslam {

// Where a snapshot goes: write() returns false on failure (the save then stops).
class StateWriter {
 public:
  virtual bool write(const void* data, std::size_t bytes) = 0;

 protected:
  ~StateWriter() = default;
};

// Where a snapshot comes from: read() fills exactly `bytes` or returns false.
class StateReader {
 public:
  virtual bool read(void* data, std::size_t bytes) = 0;

 protected:
  ~StateReader() = default;
};

// One pass over an engine's state, writing or reading it (see the file comment).
// Errors stick: after the first, every call does nothing and why() names it.
class StateIo {
 public:
  StateIo(StateWriter& writer, unsigned char* arena_base, std::size_t arena_bytes)
      : writer_(&writer), base_(arena_base), arena_bytes_(arena_bytes) {}
  StateIo(StateReader& reader, unsigned char* arena_base, std::size_t arena_bytes)
      : reader_(&reader), base_(arena_base), arena_bytes_(arena_bytes) {}

  bool saving() const { return writer_ != nullptr; }
  bool ok() const { return why_[0] == '\0'; }
  const char* why() const { return why_; }
  std::uint64_t byte_count() const { return bytes_; }

  // Raw bytes of a member.
  void bytes(void* data, std::size_t n);
  // A trivially copyable member (a scalar, a POD struct, an array of them).
  template <class T>
  void value(T& v) {
    static_assert(std::is_trivially_copyable<T>::value, "StateIo::value: trivially copyable members only");
    static_assert(!std::is_pointer<T>::value, "StateIo::value: pointers go through arena_pointer()");
    bytes(&v, sizeof v);
  }
  // A pointer into the arena (or null), as its offset from the arena's base. A pointer
  // elsewhere cannot be saved: that is a failure naming `what`.
  template <class T>
  void arena_pointer(T*& p, const char* what) {
    std::uint64_t off = kNull;
    if (saving()) {
      if (p != nullptr) {
        const auto* c = reinterpret_cast<const unsigned char*>(p);
        if (base_ == nullptr || c < base_ || c > base_ + arena_bytes_) {
          fail("pointer outside the arena", what);
          return;
        }
        off = static_cast<std::uint64_t>(c - base_);
      }
      value(off);
      return;
    }
    value(off);
    if (!ok()) return;
    if (off == kNull) {
      p = nullptr;
    } else if (off > arena_bytes_) {
      fail("pointer offset outside the arena", what);
    } else {
      p = reinterpret_cast<T*>(base_ + off);
    }
  }
  // A value init() fixed (a capacity): written, or read and compared with this
  // engine's; a stream whose value differs fails, naming `what`.
  template <class T>
  void fixed(const T& v, const char* what) {
    T theirs = v;
    value(theirs);
    if (ok() && !(theirs == v)) fail(what, "differs from this engine's");
  }
  // A part's name (up to 15 characters): written, or read and compared.
  void section(const char* name);
  void fail(const char* reason, const char* what);

 private:
  static constexpr std::uint64_t kNull = ~std::uint64_t{0};
  StateWriter* writer_ = nullptr;
  StateReader* reader_ = nullptr;
  unsigned char* base_ = nullptr;
  std::size_t arena_bytes_ = 0U;
  std::uint64_t bytes_ = 0U;
  char why_[120] = {};
};

}  // namespace sdpslam
