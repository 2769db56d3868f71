#include "sdpslam/core/state_io.h"

namespace sdpslam {
namespace {

// strncat without the library's locale or heap: appends `s` within `n` bytes of `out`.
void append(char* out, std::size_t n, const char* s) {
  std::size_t len = 0U;
  while (len + 1U < n && out[len] != '\0') ++len;
  while (len + 1U < n && s != nullptr && *s != '\0') out[len++] = *s++;
  out[len] = '\0';
}

}  // namespace

void StateIo::bytes(void* data, std::size_t n) {
  if (!ok() || n == 0U) return;
  const bool done = writer_ != nullptr ? writer_->write(data, n) : reader_->read(data, n);
  if (!done) {
    fail(writer_ != nullptr ? "write failed" : "stream ends early or cannot be read", nullptr);
    return;
  }
  bytes_ += n;
}

void StateIo::section(const char* name) {
  char tag[16] = {};
  for (std::size_t i = 0; i + 1U < sizeof tag && name[i] != '\0'; ++i) tag[i] = name[i];
  if (saving()) {
    bytes(tag, sizeof tag);
    return;
  }
  char got[16] = {};
  bytes(got, sizeof got);
  if (ok() && std::memcmp(tag, got, sizeof tag) != 0) fail("not written by this build (part missing)", name);
}

void StateIo::fail(const char* reason, const char* what) {
  if (!ok()) return;
  why_[0] = '\0';
  append(why_, sizeof why_, reason);
  if (what != nullptr) {
    append(why_, sizeof why_, ": ");
    append(why_, sizeof why_, what);
  }
  if (why_[0] == '\0') why_[0] = '?';
}

}  // namespace sdpslam
