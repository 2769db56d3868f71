#pragma once
// Atomic file replacement: write to a temporary file in the same directory, flush,
// fsync, rename over the target (and fsync the directory). A reader of `path` sees
// either the old complete file or the new complete file, never a torn one, even if the
// process dies mid-write.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <string>

namespace sdpslam::io {

// kDurable: fsync of the file before the rename and of the directory after it, so the
// new file survives a power cut. kAtomicOnly: the rename alone, so a reader still sees
// one complete file or the other, but a power cut may bring back the previous one; for a
// file rewritten every few seconds whose next version replaces it anyway (a heartbeat),
// where a flush to the storage each time is only wear and CPU.
enum class Sync : std::uint8_t { kDurable, kAtomicOnly };

// Writes `contents` to `path` atomically. False iff any step failed; `error` then names
// the path and the failing call with strerror. On failure the old file is untouched and
// the temporary is removed.
bool write_file_atomic(const std::string& path, const std::string& contents, std::string* error,
                       Sync sync = Sync::kDurable);

// fsync(2) calls this module has made in this process (files and directories), for
// tests and status figures.
std::uint64_t fsync_count();

// Streaming variant for large outputs (logs): write through stream(), then commit().
// Destroying an uncommitted file removes the temporary; the target is never touched.
class AtomicOutputFile {
 public:
  AtomicOutputFile() = default;
  ~AtomicOutputFile();
  AtomicOutputFile(const AtomicOutputFile&) = delete;
  AtomicOutputFile& operator=(const AtomicOutputFile&) = delete;

  // Creates the temporary beside `path`. False (with `error`) iff that fails.
  bool open(const std::string& path, std::string* error);
  std::FILE* stream() { return file_; }
  // Flushes, fsyncs (kDurable), renames over the target. False iff any step or any
  // earlier write failed (checked through ferror), with `error` naming the path and the
  // cause.
  bool commit(std::string* error, Sync sync = Sync::kDurable);
  // Drops the temporary without touching the target.
  void abandon();

 private:
  // The stream writes through write(2) on fd_ and keeps the first error's errno (stdio
  // does not), so a full disk is reported as "No space left on device".
  static long write_to_fd(void* self, const char* data, std::size_t size);
  static int close_fd(void* self);

  std::FILE* file_ = nullptr;
  int fd_ = -1;
  int write_errno_ = 0;
  std::string path_;
  std::string temp_path_;
};

// Makes renames in `dir` durable (fsync of the directory). Some file systems refuse fsync
// on a directory (EINVAL, EROFS): not a failure, the renames have happened. False (with
// `error`) iff it cannot be opened or fsync fails otherwise.
bool fsync_directory(const std::string& dir, std::string* error);

// Creates `dir` and its parents if missing. False (with `error`) iff that fails.
bool make_directories(const std::string& dir, std::string* error);

}  // namespace sdpslam::io
