#include "sdpslam/io/snapshot_file.h"

#include <zlib.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <vector>

#include "sdpslam/core/version.h"
#include "sdpslam/io/atomic_file.h"

namespace sdpslam::io {
namespace {

constexpr char kMagic[16] = {'S', 'D', 'P', 'S', 'L', 'A', 'M', ' ', 'S', 'N', 'A', 'P', 'S', 'H', 'O', 'T'};
constexpr char kEnd[4] = {'E', 'N', 'D', '.'};
constexpr std::uint32_t kFileFormat = 1U;
constexpr std::uint32_t kDeflate = 1U;
constexpr std::size_t kTrailerBytes = 8U + 8U + 4U + 4U;
constexpr std::size_t kChunk = 1U << 16;

void put_le(std::string* out, std::uint64_t v, int bytes) {
  for (int i = 0; i < bytes; ++i) out->push_back(static_cast<char>((v >> (8 * i)) & 0xFFU));
}
std::uint64_t get_le(const unsigned char* p, int bytes) {
  std::uint64_t v = 0U;
  for (int i = bytes - 1; i >= 0; --i) v = (v << 8) | p[i];
  return v;
}

std::string header_bytes(std::uint64_t fingerprint) {
  std::string h(kMagic, sizeof kMagic);
  put_le(&h, kFileFormat, 4);
  const std::string version = version_string();
  put_le(&h, version.size(), 4);
  h += version;
  put_le(&h, fingerprint, 8);
  put_le(&h, kDeflate, 4);
  return h;
}

std::string describe_errno(const std::string& path, const char* call) {
  return path + ": " + call + ": " + std::strerror(errno);
}

// Reads the header from `f`; false with `error` naming what is wrong.
bool read_header(std::FILE* f, const std::string& path, SnapshotInfo* info, std::string* error) {
  unsigned char fixed[16 + 4 + 4];
  if (std::fread(fixed, 1, sizeof fixed, f) != sizeof fixed || std::memcmp(fixed, kMagic, sizeof kMagic) != 0) {
    *error = path + ": not a snapshot file";
    return false;
  }
  const auto format = static_cast<std::uint32_t>(get_le(fixed + 16, 4));
  if (format != kFileFormat) {
    *error = path + ": snapshot file format " + std::to_string(format) + ", this program reads " +
             std::to_string(kFileFormat);
    return false;
  }
  const std::uint64_t version_bytes = get_le(fixed + 20, 4);
  if (version_bytes > 256U) {
    *error = path + ": corrupt snapshot header";
    return false;
  }
  std::string version(static_cast<std::size_t>(version_bytes), '\0');
  unsigned char rest[8 + 4];
  if (std::fread(&version[0], 1, version.size(), f) != version.size() || std::fread(rest, 1, sizeof rest, f) != sizeof rest) {
    *error = path + ": snapshot header cut short";
    return false;
  }
  info->version = version;
  info->config_fingerprint = get_le(rest, 8);
  if (get_le(rest + 8, 4) != kDeflate) {
    *error = path + ": unknown snapshot compression";
    return false;
  }
  return true;
}

}  // namespace

std::uint64_t fingerprint(const std::string& text, std::uint64_t hash) {
  for (const char c : text) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 0x100000001B3ULL;
  }
  return hash;
}

// ---- writing --------------------------------------------------------------------------

struct SnapshotOut::Impl {
  AtomicOutputFile file;
  z_stream z{};
  bool z_open = false;
  bool failed = false;
  std::string path;
  std::uint32_t crc = 0U;
  std::uint64_t payload = 0U;
  std::uint64_t body = 0U;
  std::uint64_t header = 0U;
  std::vector<unsigned char> out = std::vector<unsigned char>(kChunk);

  bool emit(const void* data, std::size_t n) {
    if (n == 0U) return true;
    crc = static_cast<std::uint32_t>(crc32(crc, static_cast<const Bytef*>(data), static_cast<uInt>(n)));
    if (std::fwrite(data, 1, n, file.stream()) != n) failed = true;
    return !failed;
  }
  // Runs deflate over the pending input with `flush`, writing what it produces.
  bool pump(int flush) {
    for (;;) {
      z.next_out = out.data();
      z.avail_out = static_cast<uInt>(out.size());
      const int rc = deflate(&z, flush);
      if (rc == Z_STREAM_ERROR) return failed = true, false;
      const std::size_t produced = out.size() - z.avail_out;
      body += produced;
      if (!emit(out.data(), produced)) return false;
      if (flush == Z_FINISH ? rc == Z_STREAM_END : z.avail_out != 0U) return true;
    }
  }
};

SnapshotOut::SnapshotOut() : impl_(std::make_unique<Impl>()) {}
SnapshotOut::~SnapshotOut() {
  if (impl_->z_open) deflateEnd(&impl_->z);
}

bool SnapshotOut::open(const std::string& path, std::uint64_t fp, std::string* error) {
  impl_->path = path;
  if (!impl_->file.open(path, error)) return false;
  // Level 1: the arena is mostly pool slots never used, which the fastest level already
  // shrinks several times over; the snapshot is written while the robot maps.
  if (deflateInit(&impl_->z, 1) != Z_OK) {
    *error = path + ": zlib deflateInit failed";
    return false;
  }
  impl_->z_open = true;
  const std::string h = header_bytes(fp);
  impl_->header = h.size();
  return impl_->emit(h.data(), h.size());
}

bool SnapshotOut::write(const void* data, std::size_t bytes) {
  Impl& m = *impl_;
  if (m.failed || !m.z_open) return false;
  const auto* p = static_cast<const unsigned char*>(data);
  while (bytes > 0U) {
    // avail_in is 32-bit in zlib: feed at most 1 GiB at a time.
    const std::size_t n = bytes < (std::size_t{1} << 30) ? bytes : (std::size_t{1} << 30);
    m.z.next_in = const_cast<Bytef*>(p);
    m.z.avail_in = static_cast<uInt>(n);
    if (!m.pump(Z_NO_FLUSH)) return false;
    m.payload += n;
    p += n;
    bytes -= n;
  }
  return true;
}

bool SnapshotOut::commit(std::string* error) {
  Impl& m = *impl_;
  if (!m.failed && m.z_open) {
    m.z.next_in = nullptr;
    m.z.avail_in = 0U;
    m.pump(Z_FINISH);
  }
  if (m.failed) {
    *error = m.path + ": snapshot not written (write or compression failed)";
    m.file.abandon();
    return false;
  }
  std::string t;
  put_le(&t, m.payload, 8);
  put_le(&t, m.body, 8);
  const std::uint32_t crc = m.crc;  // of header and body; the trailer is not covered
  put_le(&t, crc, 4);
  t.append(kEnd, sizeof kEnd);
  if (std::fwrite(t.data(), 1, t.size(), m.file.stream()) != t.size()) m.failed = true;
  if (m.failed) {
    *error = describe_errno(m.path, "write");
    m.file.abandon();
    return false;
  }
  return m.file.commit(error);
}

std::uint64_t SnapshotOut::payload_bytes() const { return impl_->payload; }
std::uint64_t SnapshotOut::file_bytes() const { return impl_->header + impl_->body + kTrailerBytes; }

// ---- checking ---------------------------------------------------------------------------

bool check_snapshot(const std::string& path, std::uint64_t fp, SnapshotInfo* info, std::string* error) {
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) {
    *error = describe_errno(path, "open");
    return false;
  }
  struct Closer {
    std::FILE* f;
    ~Closer() { std::fclose(f); }
  } closer{f};
  if (!read_header(f, path, info, error)) return false;
  const long header_end = std::ftell(f);
  if (std::fseek(f, 0, SEEK_END) != 0) {
    *error = describe_errno(path, "seek");
    return false;
  }
  const long size = std::ftell(f);
  info->file_bytes = static_cast<std::uint64_t>(size);
  if (header_end < 0 || size < header_end + static_cast<long>(kTrailerBytes)) {
    *error = path + ": snapshot cut short (no trailer)";
    return false;
  }
  std::rewind(f);
  std::uint32_t crc = 0U;
  std::vector<unsigned char> buf(kChunk);
  long left = size - static_cast<long>(kTrailerBytes);
  while (left > 0) {
    const std::size_t n = static_cast<std::size_t>(left < static_cast<long>(buf.size()) ? left : static_cast<long>(buf.size()));
    if (std::fread(buf.data(), 1, n, f) != n) {
      *error = describe_errno(path, "read");
      return false;
    }
    crc = static_cast<std::uint32_t>(crc32(crc, buf.data(), static_cast<uInt>(n)));
    left -= static_cast<long>(n);
  }
  unsigned char t[kTrailerBytes];
  if (std::fread(t, 1, sizeof t, f) != sizeof t || std::memcmp(t + 20, kEnd, sizeof kEnd) != 0) {
    *error = path + ": snapshot cut short or corrupt (no trailer)";
    return false;
  }
  info->payload_bytes = get_le(t, 8);
  const std::uint64_t body = get_le(t + 8, 8);
  if (body != static_cast<std::uint64_t>(size - header_end) - kTrailerBytes) {
    *error = path + ": snapshot corrupt (body size differs from the trailer's)";
    return false;
  }
  if (get_le(t + 16, 4) != crc) {
    *error = path + ": snapshot corrupt (CRC-32 mismatch)";
    return false;
  }
  if (info->version != version_string()) {
    *error = path + ": snapshot written by sdpslam " + info->version + ", this is " + version_string();
    return false;
  }
  if (info->config_fingerprint != fp) {
    *error = path + ": snapshot written with another configuration";
    return false;
  }
  return true;
}

bool keep_snapshot_aside(const std::string& path, std::string* aside, std::string* error) {
  *aside = path + ".refused";
  if (std::rename(path.c_str(), aside->c_str()) != 0) {
    *error = describe_errno(path, "rename");
    return false;
  }
  return true;
}

// ---- reading ----------------------------------------------------------------------------

struct SnapshotIn::Impl {
  std::FILE* f = nullptr;
  z_stream z{};
  bool z_open = false;
  bool ended = false;  // the deflate stream's end was reached
  std::uint64_t body_left = 0U;
  std::vector<unsigned char> in = std::vector<unsigned char>(kChunk);
  ~Impl() {
    if (z_open) inflateEnd(&z);
    if (f != nullptr) std::fclose(f);
  }
};

SnapshotIn::SnapshotIn() : impl_(std::make_unique<Impl>()) {}
SnapshotIn::~SnapshotIn() = default;

bool SnapshotIn::open(const std::string& path, std::string* error) {
  Impl& m = *impl_;
  m.f = std::fopen(path.c_str(), "rb");
  if (m.f == nullptr) {
    *error = describe_errno(path, "open");
    return false;
  }
  SnapshotInfo info;
  if (!read_header(m.f, path, &info, error)) return false;
  const long header_end = std::ftell(m.f);
  if (std::fseek(m.f, 0, SEEK_END) != 0) {
    *error = describe_errno(path, "seek");
    return false;
  }
  const long size = std::ftell(m.f);
  if (header_end < 0 || size < header_end + static_cast<long>(kTrailerBytes) || std::fseek(m.f, header_end, SEEK_SET) != 0) {
    *error = path + ": snapshot cut short";
    return false;
  }
  m.body_left = static_cast<std::uint64_t>(size - header_end) - kTrailerBytes;
  if (inflateInit(&m.z) != Z_OK) {
    *error = path + ": zlib inflateInit failed";
    return false;
  }
  m.z_open = true;
  return true;
}

bool SnapshotIn::read(void* data, std::size_t bytes) {
  Impl& m = *impl_;
  if (!m.z_open) return false;
  auto* p = static_cast<unsigned char*>(data);
  while (bytes > 0U) {
    if (m.ended) return false;
    if (m.z.avail_in == 0U && m.body_left > 0U) {
      const std::size_t n = static_cast<std::size_t>(m.body_left < m.in.size() ? m.body_left : m.in.size());
      if (std::fread(m.in.data(), 1, n, m.f) != n) return false;
      m.body_left -= n;
      m.z.next_in = m.in.data();
      m.z.avail_in = static_cast<uInt>(n);
    }
    const std::size_t n = bytes < (std::size_t{1} << 30) ? bytes : (std::size_t{1} << 30);
    m.z.next_out = p;
    m.z.avail_out = static_cast<uInt>(n);
    const int rc = inflate(&m.z, Z_NO_FLUSH);
    if (rc == Z_STREAM_END) m.ended = true;
    else if (rc != Z_OK && !(rc == Z_BUF_ERROR && m.body_left > 0U)) return false;
    const std::size_t got = n - m.z.avail_out;
    if (got == 0U && m.z.avail_in == 0U && m.body_left == 0U) return false;
    p += got;
    bytes -= got;
  }
  return true;
}

bool SnapshotIn::get_bytes(std::string* out, std::uint64_t max_bytes) {
  std::uint64_t n = 0U;
  if (!get_u64(&n) || n > max_bytes) return false;
  out->assign(static_cast<std::size_t>(n), '\0');
  return n == 0U || read(&(*out)[0], static_cast<std::size_t>(n));
}

bool SnapshotIn::at_end() {
  Impl& m = *impl_;
  if (!m.ended) {
    unsigned char probe = 0U;
    if (read(&probe, 1U)) return false;  // more payload than was read
  }
  return m.ended && m.z.avail_in == 0U && m.body_left == 0U;
}

}  // namespace sdpslam::io
