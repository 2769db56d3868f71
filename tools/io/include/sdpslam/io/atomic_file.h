#pragma once
// Atomic file replacement: write to a temporary file in the same directory, flush,
// fsync, rename over the target (and fsync the directory). A reader of `path` sees
// either the old complete file or the new complete file, never a torn one, even if the
// process dies mid-write.
#include <cstddef>
#include <cstdio>
#include <string>

namespace sdpslam::io {

// Writes `contents` to `path` atomically. False iff any step failed; `error` then names
// the path and the failing call with strerror. On failure the old file is untouched and
// the temporary is removed.
bool write_file_atomic(const std::string& path, const std::string& contents, std::string* error);

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
  // Flushes, fsyncs, renames over the target. False iff any step or any earlier write
  // failed (checked through ferror), with `error` naming the path and the cause.
  bool commit(std::string* error);
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
