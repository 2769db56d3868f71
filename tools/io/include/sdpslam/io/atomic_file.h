#pragma once
// Atomic file replacement: write to a temporary file in the same directory, flush,
// fsync, rename over the target (and fsync the directory). A reader of `path` sees
// either the old complete file or the new complete file, never a torn one, even if the
// process dies mid-write.
#include <string>

namespace sdpslam::io {

// Writes `contents` to `path` atomically. False iff any step failed; `error` then names
// the path and the failing call with strerror. On failure the old file is untouched and
// the temporary is removed.
bool write_file_atomic(const std::string& path, const std::string& contents, std::string* error);

// Creates `dir` and its parents if missing. False (with `error`) iff that fails.
bool make_directories(const std::string& dir, std::string* error);

}  // namespace sdpslam::io
