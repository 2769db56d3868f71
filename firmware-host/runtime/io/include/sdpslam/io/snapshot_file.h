#pragma once
// Snapshot files: a program's state and the SLAM engine's (SdpSlam::save_state) in one
// file that is written atomically and checked whole before anything is read from it.
//
// Layout:
//   header   "SDPSLAM SNAPSHOT" (16 bytes), file format (u32), the writing program's
//            version (u32 length + text), the configuration's fingerprint (u64: the
//            caller's hash of every option that shapes the state), compression (u32,
//            1 = zlib deflate);
//   body     the payload, deflated: the program's part first, then the engine's;
//   trailer  payload bytes (u64), body bytes (u64), CRC-32 of header and body (u32),
//            "END." (4 bytes).
// Integers are little-endian. The file is staged beside its path and renamed over it
// (io::AtomicOutputFile, fsync'd), so a reader finds the previous complete snapshot or
// the new one. check_snapshot() reads it once to verify the trailer, the CRC, the
// version and the fingerprint; only then does SnapshotIn read the payload.
#include <cstdint>
#include <memory>
#include <string>
#include <type_traits>
#include <vector>

#include "sdpslam/core/state_io.h"

namespace sdpslam::io {

// FNV-1a, 64 bit, for configuration fingerprints: feed the text of every option.
std::uint64_t fingerprint(const std::string& text, std::uint64_t hash = 0xCBF29CE484222325ULL);

struct SnapshotInfo {
  std::string version;            // of the program that wrote it
  std::uint64_t config_fingerprint = 0U;
  std::uint64_t payload_bytes = 0U;  // before compression
  std::uint64_t file_bytes = 0U;
};

// Verifies the file at `path` as a whole: layout, trailer, CRC, that it was written by
// this version of the program (sdpslam::version()) with configuration `fingerprint`.
// False with `error` saying which check failed (and both versions or fingerprints).
bool check_snapshot(const std::string& path, std::uint64_t fingerprint, SnapshotInfo* info, std::string* error);

// Moves a refused snapshot aside (PATH.refused, replacing an older one) so that it is
// kept for inspection but never read again. False with `error` iff the rename fails.
bool keep_snapshot_aside(const std::string& path, std::string* aside, std::string* error);

// Writing: open(), the payload through write() (the program's part with the helpers,
// then SdpSlam::save_state(*this)), commit().
class SnapshotOut final : public StateWriter {
 public:
  SnapshotOut();
  ~SnapshotOut();
  SnapshotOut(const SnapshotOut&) = delete;
  SnapshotOut& operator=(const SnapshotOut&) = delete;

  bool open(const std::string& path, std::uint64_t fingerprint, std::string* error);
  bool write(const void* data, std::size_t bytes) override;
  void put_u64(std::uint64_t v) { write(&v, sizeof v); }
  void put_bytes(const void* data, std::size_t bytes) {
    put_u64(bytes);
    write(data, bytes);
  }
  // Finishes the body and the trailer, then replaces the file. False with `error` iff
  // any write failed (nothing is replaced then).
  bool commit(std::string* error);
  std::uint64_t payload_bytes() const;
  std::uint64_t file_bytes() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Reading a file check_snapshot() accepted.
class SnapshotIn final : public StateReader {
 public:
  SnapshotIn();
  ~SnapshotIn();
  SnapshotIn(const SnapshotIn&) = delete;
  SnapshotIn& operator=(const SnapshotIn&) = delete;

  bool open(const std::string& path, std::string* error);
  bool read(void* data, std::size_t bytes) override;
  bool get_u64(std::uint64_t* v) { return read(v, sizeof *v); }
  // A block put_bytes() wrote, of at most `max_bytes`.
  bool get_bytes(std::string* out, std::uint64_t max_bytes);
  // True iff the whole payload was read (nothing left over).
  bool at_end();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A vector of plain records: its byte count, then its bytes (this machine's layout, as
// the engine's part: a snapshot is read back by the same build).
template <class T>
void put_vector(SnapshotOut& out, const std::vector<T>& v) {
  static_assert(std::is_trivially_copyable<T>::value, "put_vector: plain records only");
  out.put_bytes(v.data(), v.size() * sizeof(T));
}
template <class T>
bool get_vector(SnapshotIn& in, std::vector<T>* v, std::uint64_t max_elements = std::uint64_t{1} << 32) {
  static_assert(std::is_trivially_copyable<T>::value, "get_vector: plain records only");
  std::uint64_t bytes = 0U;
  if (!in.get_u64(&bytes) || bytes % sizeof(T) != 0U || bytes / sizeof(T) > max_elements) return false;
  const auto n = static_cast<std::size_t>(bytes / sizeof(T));
  if (v->capacity() < n) v->reserve(n);
  v->resize(n);
  return n == 0U || in.read(v->data(), n * sizeof(T));
}

}  // namespace sdpslam::io
