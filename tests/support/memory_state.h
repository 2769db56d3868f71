#pragma once
// Snapshot streams in memory (core/state_io.h), for tests that write a state and read it
// back: the writer keeps every byte, the reader reads them back and says how far it got.
#include <cstddef>
#include <cstring>
#include <vector>

#include "sdpslam/core/state_io.h"

namespace sdpslam::test {

class MemoryWriter final : public StateWriter {
 public:
  bool write(const void* data, std::size_t bytes) override {
    const auto* p = static_cast<const unsigned char*>(data);
    bytes_.insert(bytes_.end(), p, p + bytes);
    return true;
  }
  std::vector<unsigned char> bytes_;
};

class MemoryReader final : public StateReader {
 public:
  explicit MemoryReader(const std::vector<unsigned char>& bytes) : bytes_(bytes) {}
  bool read(void* data, std::size_t bytes) override {
    if (bytes > bytes_.size() - at_) return false;
    std::memcpy(data, bytes_.data() + at_, bytes);
    at_ += bytes;
    return true;
  }
  std::size_t at_ = 0U;

 private:
  const std::vector<unsigned char>& bytes_;
};

}  // namespace sdpslam::test
